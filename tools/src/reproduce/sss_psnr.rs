//! realtime-sss-thesis Table 7.3's PSNR column: per frame, the PSNR of luminance over the
//! subsurface pixels of a method's frame against the converged pass of the same run (the
//! thesis's ground truth is its own pass at 1024 spp per frame, Sec. 7.4, so the PSNR measures
//! the sampling's noise, not the diffusion model's error). The subsurface pixels are those the
//! reference pass sampled (its `sample_count` image non-zero); the peak is the reference's
//! largest luminance over those pixels and the run's frames, one constant per run, so that a
//! difference of two methods' PSNR is the ratio of their errors whatever the peak.

use std::path::Path;

use anyhow::{Context, Result, bail};
use systems::run_folder::RunFolder;

use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;

fn luminance_image(path: &Path) -> Result<Vec<f32>> {
    let image = metrics::load_image(path)?;
    Ok(image.rgb.iter().map(|p| sss::sampling::luminance(*p)).collect())
}

fn sampled(path: &Path) -> Result<Vec<bool>> {
    let image = metrics::load_image(path)?;
    Ok(image.rgb.iter().map(|p| p.iter().any(|c| *c > 0.0)).collect())
}

/// Per method of `run` other than `against`, the per-frame PSNR (dB) against `against`'s frames
/// of the same run, `frames` frames from the run folder; `against`'s own series stays empty
/// (no PSNR against itself).
pub fn add(run: &mut SeedRun, against: &str, frames: u32) -> Result<()> {
    let Some(root) = &run.folder else {
        bail!("seed {}: no run folder to read {} from", run.seed, Metric::shipped("SssPsnr").name())
    };
    let folder = RunFolder::new(root);
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
    let methods: Vec<String> = run.methods.keys().filter(|m| *m != against).cloned().collect();
    for m in methods {
        let mut series = Vec::with_capacity(frames as usize);
        for f in 0..frames as usize {
            let image = luminance_image(&folder.frame(&m, f as u32, "exr"))
                .with_context(|| at(&format!("{m}'s frame"), f as u32))?;
            let any = masks[f].iter().any(|s| *s);
            let db = sss::evaluation::psnr_luminance(&image, &references[f], &masks[f], peak);
            series.push((any && peak > 0.0).then_some(db));
        }
        let metrics = run.methods.get_mut(&m).expect("a method of the run");
        metrics.insert(Metric::shipped("SssPsnr").name().to_string(), series);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use systems::output::{write_exr, write_png_linear};

    fn grey(values: &[f32]) -> Vec<[f32; 4]> {
        values.iter().map(|&v| [v, v, v, 1.0]).collect()
    }

    /// PSNR over the reference's sampled pixels only, the peak its largest luminance there (the
    /// unsampled pixel's 9.0 neither counts nor sets the peak); the reference gets no series.
    #[test]
    fn psnr_over_the_sampled_pixels_against_the_reference() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let folder = RunFolder::new(&dir);
        for f in 0..2 {
            write_exr(&folder.frame("ref", f, "exr"), 3, 1, &grey(&[1.0, 0.5, 9.0])).unwrap();
            write_exr(&folder.frame("a", f, "exr"), 3, 1, &grey(&[0.9, 0.5, 0.0])).unwrap();
            write_exr(&folder.frame("b", f, "exr"), 3, 1, &grey(&[0.8, 0.5, 0.0])).unwrap();
            let counts = grey(&[1.0, 0.25, 0.0]);
            write_png_linear(&folder.method_image("ref", "sample_count", f, "png"), 3, 1, &counts)
                .unwrap();
        }
        let methods = ["a", "b", "ref"].map(|m| (m.to_string(), BTreeMap::new())).into();
        let mut run = SeedRun { seed: 1, methods, jod: BTreeMap::new(), folder: Some(dir.clone()) };
        add(&mut run, "ref", 2).unwrap();
        let psnr = |m: &str| run.methods[m]["sss_psnr"].clone();
        // a: MSE (0.1² + 0) / 2 = 0.005 at peak 1: 10 log10(200) = 23.0103 dB; b: MSE 0.02.
        let a = psnr("a");
        assert_eq!(a.len(), 2);
        assert!((a[0].unwrap() - 23.0103).abs() < 1e-3, "{a:?}");
        assert!((psnr("b")[1].unwrap() - 16.9897).abs() < 1e-3);
        assert!(!run.methods["ref"].contains_key("sss_psnr"));
        // A missing frame is an error naming the method and frame.
        std::fs::remove_file(folder.frame("b", 1, "exr")).unwrap();
        let e = format!("{:#}", add(&mut run, "ref", 2).unwrap_err());
        assert!(e.contains("frame 1") && e.contains("b's frame"), "{e}");
    }
}
