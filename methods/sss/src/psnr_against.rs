//! realtime-sss-thesis Table 7.3's PSNR column (`SssPsnr`, computed by `flicker reproduce` from
//! a run folder): per frame, the PSNR of luminance over the subsurface pixels of a method's
//! frame against the converged pass of the same run (the thesis's ground truth is its own pass
//! at 1024 spp per frame, Sec. 7.4, so the PSNR measures the sampling's noise, not the diffusion
//! model's error). The subsurface pixels are those the reference pass sampled (its
//! `sample_count` image non-zero); the peak is the reference's largest luminance over those
//! pixels and the run's frames, one constant per run, so that a difference of two methods' PSNR
//! is the ratio of their errors whatever the peak.

use std::path::Path;

use anyhow::{Context, Result, bail};
use frame::method::{FolderRun, FolderSeries};
use frame::run_folder::RunFolder;

/// The statistic's frames.csv-style column.
pub const COLUMN: &str = "sss_psnr";

fn luminance_image(path: &Path) -> Result<Vec<f32>> {
    let image = metrics::load_image(path)?;
    Ok(image.rgb.iter().map(|p| crate::sampling::luminance(*p)).collect())
}

fn sampled(path: &Path) -> Result<Vec<bool>> {
    let image = metrics::load_image(path)?;
    Ok(image.rgb.iter().map(|p| p.iter().any(|c| *c > 0.0)).collect())
}

/// Per method of `run` other than its `against`, the per-frame PSNR (dB) against `against`'s
/// frames of the same run; `against` itself gets no series (no PSNR against itself).
pub fn psnr_against(run: &FolderRun) -> Result<FolderSeries> {
    let Some(against) = run.against else {
        bail!("seed {}: {COLUMN} needs a reference method (the claim's against)", run.seed)
    };
    let frames = run.frames;
    let folder = RunFolder::new(run.folder);
    let at = |what: &str, f: u32| format!("seed {} frame {f}: {what}", run.seed);
    let mut references = Vec::new();
    let mut masks = Vec::new();
    for f in 0..frames {
        let mask = sampled(&folder.method_image(against, "sample_count", f, "png"))
            .with_context(|| at(&format!("{against}'s sample counts"), f))?;
        references.push(
            luminance_image(&folder.frame(against, f, "exr"))
                .with_context(|| at(&format!("{against}'s frame"), f))?,
        );
        masks.push(mask);
    }
    let peak = references
        .iter()
        .zip(&masks)
        .flat_map(|(r, m)| r.iter().zip(m).filter(|(_, m)| **m).map(|(l, _)| *l as f64))
        .fold(0.0, f64::max);
    let mut out = FolderSeries::new();
    for m in run.methods.iter().filter(|m| *m != against) {
        let mut series = Vec::with_capacity(frames as usize);
        for f in 0..frames as usize {
            let image = luminance_image(&folder.frame(m, f as u32, "exr"))
                .with_context(|| at(&format!("{m}'s frame"), f as u32))?;
            let any = masks[f].iter().any(|s| *s);
            let db = psnr_luminance(&image, &references[f], &masks[f], peak);
            series.push((any && peak > 0.0).then_some(db));
        }
        out.push((m.clone(), COLUMN, series));
    }
    Ok(out)
}

/// PSNR of luminance over the masked pixels, peak `peak`.
pub fn psnr_luminance(result: &[f32], reference: &[f32], mask: &[bool], peak: f64) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for ((r, f), _) in result.iter().zip(reference).zip(mask).filter(|(_, m)| **m) {
        let e = *r as f64 - *f as f64;
        se += e * e;
        n += 1;
    }
    let mse = se / n.max(1) as f64;
    10.0 * (peak * peak / mse.max(1e-30)).log10()
}

#[cfg(test)]
mod tests {
    use super::*;
    use frame::output::{grey_pixels, write_exr, write_png_linear};

    /// PSNR over the reference's sampled pixels only, the peak its largest luminance there (the
    /// unsampled pixel's 9.0 neither counts nor sets the peak); the reference gets no series.
    #[test]
    fn psnr_over_the_sampled_pixels_against_the_reference() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let folder = RunFolder::new(&dir);
        for f in 0..2 {
            write_exr(&folder.frame("ref", f, "exr"), 3, 1, &grey_pixels([1.0, 0.5, 9.0])).unwrap();
            write_exr(&folder.frame("a", f, "exr"), 3, 1, &grey_pixels([0.9, 0.5, 0.0])).unwrap();
            write_exr(&folder.frame("b", f, "exr"), 3, 1, &grey_pixels([0.8, 0.5, 0.0])).unwrap();
            let counts = grey_pixels([1.0, 0.25, 0.0]);
            write_png_linear(&folder.method_image("ref", "sample_count", f, "png"), 3, 1, &counts)
                .unwrap();
        }
        let methods = ["a", "b", "ref"].map(String::from);
        let run = FolderRun {
            folder: &dir,
            seed: 1,
            methods: &methods,
            frames: 2,
            events: &[],
            against: Some("ref"),
        };
        let out = psnr_against(&run).unwrap();
        let psnr = |m: &str| {
            out.iter().find(|(n, c, _)| n == m && *c == "sss_psnr").map(|s| s.2.clone()).unwrap()
        };
        // a: MSE (0.1² + 0) / 2 = 0.005 at peak 1: 10 log10(200) = 23.0103 dB; b: MSE 0.02.
        let a = psnr("a");
        assert_eq!(a.len(), 2);
        assert!((a[0].unwrap() - 23.0103).abs() < 1e-3, "{a:?}");
        assert!((psnr("b")[1].unwrap() - 16.9897).abs() < 1e-3);
        assert!(!out.iter().any(|(m, _, _)| m == "ref"));
        // A missing frame is an error naming the method and frame.
        std::fs::remove_file(folder.frame("b", 1, "exr")).unwrap();
        let e = format!("{:#}", psnr_against(&run).unwrap_err());
        assert!(e.contains("frame 1") && e.contains("b's frame"), "{e}");
    }
}
