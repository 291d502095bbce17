//! σ by region (reliability-weighted-nirc Fig. 3: the High-LR predictor is preferred where the
//! scene changed). Pixels are ranked by how much the path-traced reference changed across the
//! case's first event: the relative luminance change |a − b| / (a + b) of 9x9 box means (a
//! reference pixel alone is Monte Carlo noise; the reliability grid's cells span several pixels
//! too) between the frame before the event and the run's last frame. `SigmaChanged` is a
//! blend's mean σ, per frame, over the fifth of the pixels that changed most, `SigmaUnchanged`
//! over the fifth that changed least; σ is read from the blend's preference maps (green = σ,
//! black = no query answered). Only the pixels the blend answered in the frame before the event
//! are ranked: a light seen directly has no query, and its pixels, bright in both frames, would
//! otherwise be the "unchanged" fifth. Each seed ranks its own references.

use anyhow::{Context, Result, bail};
use frame::method::{FolderRun, FolderSeries};
use frame::run_folder::RunFolder;

/// The statistics' columns: σ over the pixels that changed most, and least.
pub const CHANGED: &str = "sigma_changed";
pub const UNCHANGED: &str = "sigma_unchanged";

/// The share of the pixels in each class (the most and the least changed).
const SHARE: f64 = 0.2;
/// Half-width of the box the references are averaged over (9x9).
const RADIUS: i64 = 4;

/// Which of the `ranked` pixels changed most (`Some(true)`), least (`Some(false)`) or neither,
/// from the luminance of the reference before (`before`) and after (`after`) the change; the
/// pixels not ranked are in neither class.
pub fn classes(before: &[f64], after: &[f64], width: usize, ranked: &[bool]) -> Vec<Option<bool>> {
    let (b, a) = (box_mean(before, width), box_mean(after, width));
    let change: Vec<f64> = b
        .iter()
        .zip(&a)
        .map(|(b, a)| if a + b > 1e-6 { (a - b).abs() / (a + b) } else { 0.0 })
        .collect();
    let mut sorted: Vec<f64> =
        change.iter().zip(ranked).filter(|(_, r)| **r).map(|(c, _)| *c).collect();
    if sorted.is_empty() {
        return vec![None; change.len()];
    }
    sorted.sort_by(f64::total_cmp);
    let at = |q: f64| sorted[(q * (sorted.len() - 1) as f64) as usize];
    let (low, high) = (at(SHARE), at(1.0 - SHARE));
    change
        .iter()
        .zip(ranked)
        .map(|(&c, &r)| match r {
            true if c >= high => Some(true),
            true if c <= low => Some(false),
            _ => None,
        })
        .collect()
}

fn box_mean(image: &[f64], width: usize) -> Vec<f64> {
    let height = (image.len() / width) as i64;
    let w = width as i64;
    let mut out = Vec::with_capacity(image.len());
    for y in 0..height {
        for x in 0..w {
            let (mut sum, mut n) = (0.0, 0.0);
            for yy in (y - RADIUS).max(0)..(y + RADIUS + 1).min(height) {
                for xx in (x - RADIUS).max(0)..(x + RADIUS + 1).min(w) {
                    sum += image[(yy * w + xx) as usize];
                    n += 1.0;
                }
            }
            out.push(sum / n);
        }
    }
    out
}

/// An image's Rec. 709 luminance per pixel, and its width.
fn luminance(path: &std::path::Path) -> Result<(Vec<f64>, usize)> {
    let image = metrics::load_image(path)?;
    let lum = image.rgb.iter().map(|p| (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) as f64);
    Ok((lum.collect(), image.width as usize))
}

/// A preference map's σ per pixel, `None` where no query was answered (black).
fn sigma_map(path: &std::path::Path, pixels: usize) -> Result<Vec<Option<f64>>> {
    let image = metrics::load_image(path)?;
    if image.rgb.len() != pixels {
        bail!("{}: {} pixels, the references {pixels}", path.display(), image.rgb.len());
    }
    Ok(image.rgb.iter().map(|p| (p[0] > 0.0 || p[1] > 0.0).then_some(p[1] as f64)).collect())
}

/// Mean σ over the answered pixels of each class in one preference map: (changed, unchanged).
fn sigma_by_class(path: &std::path::Path, classes: &[Option<bool>]) -> Result<[Option<f64>; 2]> {
    let sigma = sigma_map(path, classes.len())?;
    let mut sums = [(0.0, 0usize); 2];
    for (s, class) in sigma.iter().zip(classes) {
        if let (Some(changed), Some(s)) = (class, s) {
            let sum = &mut sums[usize::from(!changed)];
            sum.0 += s;
            sum.1 += 1;
        }
    }
    Ok(sums.map(|(s, n)| (n > 0).then(|| s / n as f64)))
}

/// `SigmaChanged` and `SigmaUnchanged` per frame of every method of `run` that wrote
/// preference maps (the blends and the switch), ranked across the case's first event.
pub fn sigma_by_region(run: &FolderRun) -> Result<FolderSeries> {
    let (frames, events) = (run.frames, run.events);
    let folder = RunFolder::new(run.folder);
    let Some(&event) = events.first().filter(|e| **e > 0 && **e < frames) else {
        bail!("seed {}: σ by region needs an event after the first recorded frame", run.seed)
    };
    let at = |f: u32| format!("seed {}: the reference of frame {f}", run.seed);
    let (before, width) =
        luminance(&folder.reference(event - 1, "exr")).with_context(|| at(event - 1))?;
    let (after, _) =
        luminance(&folder.reference(frames - 1, "exr")).with_context(|| at(frames - 1))?;
    if before.len() != after.len() {
        bail!("seed {}: the references before and after the event differ in size", run.seed);
    }
    let mut out = FolderSeries::new();
    for m in run.methods {
        let answered_before = folder.method_image(m, "preference", event - 1, "png");
        if !answered_before.exists() {
            continue;
        }
        let answered: Vec<bool> = sigma_map(&answered_before, before.len())
            .with_context(|| {
                format!("seed {} frame {}: {m}'s preference map", run.seed, event - 1)
            })?
            .iter()
            .map(Option::is_some)
            .collect();
        let classes = classes(&before, &after, width, &answered);
        let (mut changed, mut unchanged) = (Vec::new(), Vec::new());
        for f in 0..frames {
            let path = folder.method_image(m, "preference", f, "png");
            let [c, u] = sigma_by_class(&path, &classes)
                .with_context(|| format!("seed {} frame {f}: {m}'s preference map", run.seed))?;
            changed.push(c);
            unchanged.push(u);
        }
        out.push((m.clone(), CHANGED, changed));
        out.push((m.clone(), UNCHANGED, unchanged));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use frame::output::{grey_pixels, write_exr, write_png_linear};

    /// A 20x1 image whose reference brightens more to the right: of the pixels the blend answered
    /// (the four least changed, on the left, are black: no query), the right fifth is "changed",
    /// the left fifth "unchanged"; σ is averaged over each class frame by frame, and the methods
    /// without preference maps get nothing.
    #[test]
    fn sigma_over_the_pixels_that_changed_most_and_least() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let folder = RunFolder::new(&dir);
        let before = vec![1.0f32; 20];
        let after: Vec<f32> = (0..20).map(|x| 1.0 + x as f32).collect();
        for f in 0..3 {
            let reference = if f < 1 { &before } else { &after };
            write_exr(&folder.reference(f, "exr"), 20, 1, &grey_pixels(reference.iter().copied()))
                .unwrap();
            // σ rising over the frames on the right, 0.3 on the left.
            let map: Vec<[f32; 4]> = (0..20)
                .map(|x| match x {
                    0..4 => [0.0, 0.0, 0.0, 1.0],
                    x if x >= 12 => [0.2, 0.8 * (f as f32 + 1.0) / 3.0, 0.0, 1.0],
                    _ => [0.7, 0.3, 0.0, 1.0],
                })
                .collect();
            write_png_linear(&folder.method_image("blend", "preference", f, "png"), 20, 1, &map)
                .unwrap();
        }
        let methods = ["blend", "ema"].map(String::from);
        let mut run = FolderRun {
            folder: &dir,
            seed: 1,
            methods: &methods,
            frames: 3,
            events: &[1],
            against: None,
        };
        let out = sigma_by_region(&run).unwrap();
        let series = |c: &str| {
            out.iter().find(|(m, s, _)| m == "blend" && *s == c).map(|s| s.2.clone()).unwrap()
        };
        let changed = series("sigma_changed");
        // 8-bit PNG: within half a step of 255.
        for (f, s) in changed.iter().enumerate() {
            let expected = 0.8 * (f as f64 + 1.0) / 3.0;
            assert!((s.unwrap() - expected).abs() < 0.01, "frame {f}: {s:?}");
        }
        assert!(series("sigma_unchanged").iter().all(|s| (s.unwrap() - 0.3).abs() < 0.01));
        assert!(!out.iter().any(|(m, _, _)| m == "ema"));
        // Without an event inside the run there is nothing to rank by.
        run.events = &[];
        let e = sigma_by_region(&run).unwrap_err().to_string();
        assert!(e.contains("needs an event"), "{e}");
    }
}
