//! variance-trading-termination's Fig. 7 as a number: the image variance of variance bounding
//! over its bound t · unit². A static scene rendered at one path per pixel and frame gives
//! independent estimates of every pixel, so the per-pixel variance of the luminance over the
//! run's frames is the estimator's variance, which variance bounding bounds by the absolute
//! threshold (frames.csv's `variance_bound_log10`, reported by each absolute rule). Per frame f the
//! series holds mean_pixels((L_f − L̄)²) · n/(n − 1) / bound, so that its mean over all n
//! frames (window Overall) is the mean over pixels of the unbiased variance over the bound.

use std::path::Path;

use anyhow::{Context, Result, bail};
use frame::method::{FolderRun, FolderSeries};
use frame::run_folder::RunFolder;

/// The statistic's column.
pub const COLUMN: &str = "variance_over_bound";

/// The frames.csv column of each absolute rule's threshold t · unit² (luminance²), as log10
/// (frames.csv keeps 6 decimals; the bounds are 1e-6 and below).
pub const BOUND_COLUMN: &str = "variance_bound_log10";

/// An image's Rec. 709 luminance per pixel.
fn luminance(path: &Path) -> Result<Vec<f64>> {
    let image = metrics::load_image(path)?;
    let lum = image.rgb.iter().map(|p| (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) as f64);
    Ok(lum.collect())
}

/// Each method's bound t · unit² from frames.csv's frame-0 rows: the methods with a value in
/// [`BOUND_COLUMN`], in file order.
fn bounds(path: &Path) -> Result<std::collections::BTreeMap<String, f64>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let (Some(method), Some(frame)) = (column("method"), column("frame")) else {
        bail!("{}: no method and frame columns", path.display())
    };
    let Some(bound) = column(BOUND_COLUMN) else {
        bail!("{}: no {BOUND_COLUMN} column (no absolute variance bounding)", path.display())
    };
    let mut bounds = std::collections::BTreeMap::new();
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let at = || format!("{}:{}", path.display(), i + 2);
        let cell = |c: usize| cells.get(c).copied().with_context(|| format!("{}: short row", at()));
        let f: u32 = cell(frame)?.parse().with_context(|| format!("{}: frame", at()))?;
        let b = cell(bound)?;
        let b: Option<f64> = match b.is_empty() {
            true => None,
            false => Some(b.parse().with_context(|| format!("{}: '{b}' is not a number", at()))?),
        };
        if let (0, Some(b)) = (f, b) {
            bounds.insert(cell(method)?.to_string(), 10f64.powf(b));
        }
    }
    Ok(bounds)
}

/// Per method of `run` with a bound (the absolute variance-bounding rules), the series of its
/// frames; methods without a bound get none. Fewer than two frames is an error.
pub fn variance_over_bound(run: &FolderRun) -> Result<FolderSeries> {
    let frames = run.frames;
    if frames < 2 {
        bail!("{COLUMN} needs at least 2 frames, the case has {frames}");
    }
    let folder = RunFolder::new(run.folder);
    let n = frames as usize;
    let mut out = FolderSeries::new();
    for (method, bound) in bounds(&folder.frames_csv())? {
        if !run.methods.contains(&method) {
            continue;
        }
        let images = (0..frames)
            .map(|f| {
                luminance(&folder.frame(&method, f, "exr"))
                    .with_context(|| format!("seed {} frame {f}: {method}'s frame", run.seed))
            })
            .collect::<Result<Vec<_>>>()?;
        let pixels = images[0].len();
        let mean: Vec<f64> =
            (0..pixels).map(|p| images.iter().map(|i| i[p]).sum::<f64>() / n as f64).collect();
        let series = images
            .iter()
            .map(|image| {
                let sq: f64 = image.iter().zip(&mean).map(|(l, m)| (l - m) * (l - m)).sum();
                Some(sq / pixels as f64 * n as f64 / (n as f64 - 1.0) / bound)
            })
            .collect();
        out.push((method, COLUMN, series));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frame::output::{grey_pixels, write_exr};

    /// Two pixels over three frames: variances 1 (values 0, 1, 2) and 0 (constant) give a
    /// mean variance 0.5, over the bound 0.25: 2; a method without a bound gets no series.
    #[test]
    fn mean_pixel_variance_over_the_bound() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let folder = RunFolder::new(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (f, v) in [0.0f32, 1.0, 2.0].iter().enumerate() {
            write_exr(&folder.frame("vb", f as u32, "exr"), 2, 1, &grey_pixels([*v, 3.0])).unwrap();
            write_exr(&folder.frame("pt", f as u32, "exr"), 2, 1, &grey_pixels([*v, 3.0])).unwrap();
        }
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,variance_bound_log10\nvb,0,-0.602060\npt,0,\nvb,1,-0.602060\npt,1,\nvb,2,-0.602060\npt,2,\n",
        )
        .unwrap();
        let methods = ["vb", "pt"].map(String::from);
        let mut run = FolderRun {
            folder: &dir,
            seed: 1,
            methods: &methods,
            frames: 3,
            events: &[],
            against: None,
        };
        let out = variance_over_bound(&run).unwrap();
        let vb = &out.iter().find(|(m, c, _)| m == "vb" && *c == COLUMN).unwrap().2;
        // The Overall window's mean, as `flicker reproduce` takes it.
        let mean = vb.iter().map(|v| v.unwrap()).sum::<f64>() / vb.len() as f64;
        assert!((mean - 2.0).abs() < 1e-4, "{mean}");
        assert!(!out.iter().any(|(m, _, _)| m == "pt"));
        run.frames = 1;
        assert!(variance_over_bound(&run).unwrap_err().to_string().contains("at least 2 frames"));
    }
}
