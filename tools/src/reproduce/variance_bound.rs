//! variance-trading-termination's Fig. 7 as a number: the image variance of variance bounding
//! over its bound t · unit². A static scene rendered at one path per pixel and frame gives
//! independent estimates of every pixel, so the per-pixel variance of the luminance over the
//! run's frames is the estimator's variance, which variance bounding bounds by the absolute
//! threshold (frames.csv's `variance_bound_log10`, reported by each absolute rule). Per frame f the
//! series holds mean_pixels((L_f − L̄)²) · n/(n − 1) / bound, so that its mean over all n
//! frames (window Overall) is the mean over pixels of the unbiased variance over the bound.

use anyhow::{Context, Result, bail};
use systems::run_folder::RunFolder;

use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;

use super::frames_csv::rows;
use super::sigma_regions::luminance;

/// The frames.csv column of each absolute rule's threshold t · unit² (luminance²), as log10
/// (frames.csv keeps 6 decimals; the bounds are 1e-6 and below).
pub const BOUND_COLUMN: &str = "variance_bound_log10";

/// Per method with a bound (the absolute variance-bounding rules), the series of
/// `frames` frames; methods without a bound get none. Fewer than two frames is an error.
pub fn add(run: &mut SeedRun, frames: u32) -> Result<()> {
    let Some(root) = &run.folder else {
        bail!(
            "seed {}: no run folder to read {} from",
            run.seed,
            Metric::shipped("VarianceOverBound").name()
        )
    };
    if frames < 2 {
        bail!(
            "{} needs at least 2 frames, the case has {frames}",
            Metric::shipped("VarianceOverBound").name()
        );
    }
    let folder = RunFolder::new(root);
    let path = folder.frames_csv();
    let rows = rows(&path, |header| match header.iter().position(|h| *h == BOUND_COLUMN) {
        Some(c) => Ok(vec![c]),
        None => {
            bail!("{}: no {BOUND_COLUMN} column (no absolute variance bounding)", path.display())
        }
    })?;
    let mut bounds: std::collections::BTreeMap<String, f64> = Default::default();
    for (method, frame, values) in rows {
        if let (0, Some(b)) = (frame, values[0]) {
            bounds.insert(method, 10f64.powf(b));
        }
    }
    let n = frames as usize;
    for (method, bound) in bounds {
        let Some(metrics) = run.methods.get_mut(&method) else { continue };
        let images = (0..frames)
            .map(|f| {
                luminance(&folder.frame(&method, f, "exr"))
                    .map(|(l, _)| l)
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
        metrics.insert(Metric::shipped("VarianceOverBound").name().to_string(), series);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use systems::output::write_exr;

    fn grey(values: &[f32]) -> Vec<[f32; 4]> {
        values.iter().map(|&v| [v, v, v, 1.0]).collect()
    }

    /// Two pixels over three frames: variances 1 (values 0, 1, 2) and 0 (constant) give a
    /// mean variance 0.5, over the bound 0.25: 2; a method without a bound gets no series.
    #[test]
    fn mean_pixel_variance_over_the_bound() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let folder = RunFolder::new(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (f, v) in [0.0f32, 1.0, 2.0].iter().enumerate() {
            write_exr(&folder.frame("vb", f as u32, "exr"), 2, 1, &grey(&[*v, 3.0])).unwrap();
            write_exr(&folder.frame("pt", f as u32, "exr"), 2, 1, &grey(&[*v, 3.0])).unwrap();
        }
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,variance_bound_log10\nvb,0,-0.602060\npt,0,\nvb,1,-0.602060\npt,1,\nvb,2,-0.602060\npt,2,\n",
        )
        .unwrap();
        let methods = ["vb", "pt"].map(|m| (m.to_string(), BTreeMap::new())).into();
        let mut run = SeedRun { seed: 1, methods, jod: BTreeMap::new(), folder: Some(dir.clone()) };
        add(&mut run, 3).unwrap();
        let mean = run.window_mean("vb", Metric::shipped("VarianceOverBound"), 0..3).unwrap();
        assert!((mean - 2.0).abs() < 1e-4, "{mean}");
        assert!(!run.methods["pt"].contains_key("variance_over_bound"));
        assert!(add(&mut run, 1).unwrap_err().to_string().contains("at least 2 frames"));
    }
}
