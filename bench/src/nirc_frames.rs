//! The analogue of Table 1 of reliability-weighted-nirc.txt on this adapter: milliseconds per
//! whole NIRC frame (camera paths, inference, resolve, training records, the training step,
//! the EMA and the reliability grid's update; the diagnostic reliability look-up before
//! training is not timed, in any world) for High-LR only, EMA-only and the blend, and the blend's
//! cost over EMA-only as a share of EMA-only's frame (the paper: 15.37 -> 15.83 ms, +3%).
//!
//! Each predictor plays the built-in Cornell box in a world of its own, so each pays the
//! training step alone, as in the paper, where the scenario's methods share one. The worlds'
//! frames are interleaved, in an order that changes every frame (`ORDERS`), so that drift in
//! the machine's speed, the first-inference-after-training cost (docs/lab/nirc-speed.md) and whatever a
//! frame leaves behind for the next fall on all three alike. A frame's time is the sum of its
//! passes' times (`FrameRecord::passes_total_ms`: GPU timestamps, or each pass submitted alone
//! where the adapter has none). The cache starts untrained
//! (`pretrain_frames: 0`): a frame does the same work whatever the weights.

use anyhow::{Context, Result};
use frame::RunOutput;
use frame::run_folder::RunFolder;
use indicatif::ProgressBar;
use playback::play::{FrameWorld, Overrides, RunSpec};
use render::gpu::Gpu;
use sim::Scenario;
use tools::suite::welch::Sample;

/// The predictors of Table 1, in its column order.
pub const PREDICTORS: [&str; 3] = ["HighLrOnly", "EmaOnly", "Blend"];

/// The worlds' order in successive frames: all six permutations, so that over six frames each
/// world runs first, second and third twice and after each other world equally often.
const ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [0, 2, 1], [2, 1, 0], [1, 0, 2]];

#[derive(Clone, Debug, serde::Serialize)]
pub struct FrameTimes {
    pub predictor: String,
    /// Mean over the timed frames of the sum of the frame's pass times.
    pub ms_per_frame: f64,
    /// Mean of the method's own inference pass (`nirc_infer`).
    pub infer_ms: f64,
    /// Mean of every pass, in the frame's order.
    pub pass_ms: Vec<(String, f64)>,
    /// The frames' totals, in frame order.
    pub frame_ms: Vec<f64>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Table1 {
    pub scene: String,
    pub resolution: (u32, u32),
    pub warmup_frames: u32,
    pub timed_frames: u32,
    /// High-LR only, EMA-only, blend.
    pub rows: Vec<FrameTimes>,
    /// 100 x (blend - EMA-only) / EMA-only, per whole frame: the mean of the paired frames'
    /// differences over EMA-only's mean frame.
    pub blend_overhead_frame_percent: f64,
    /// The 95% interval of that mean (Student's t over the paired differences; NaN with fewer
    /// than 2 frames). Approximate as a percentage: it divides by EMA-only's mean frame as if
    /// that had no error of its own.
    pub blend_overhead_frame_percent_ci95: (f64, f64),
    /// The blend's extra inference time alone (`nirc_infer`, blend - EMA-only) over EMA-only's
    /// mean frame: the other passes do the same work for every predictor, so this share has
    /// less of the machine's noise.
    pub blend_infer_extra_frame_percent: f64,
}

fn scenario_text(resolution: (u32, u32), warmup: u32, frames: u32, predictor: &str) -> String {
    format!(
        "Scenario(\n    scene: Builtin(\"cornell_box\"),\n    resolution: ({}, {}),\n    frames: {frames},\n    warmup_frames: {warmup},\n    seed: 21,\n    max_depth: 6,\n    methods: [Nirc(spp: 1, predictor: {predictor}, pretrain_frames: 0)],\n    reference: (spp: 1, frames: None),\n)\n",
        resolution.0, resolution.1
    )
}

/// The scratch folder of the worlds' run folders: created new (an existing folder is refused, so
/// nothing of anyone's is removed) and removed when dropped, whether the bench finished or not.
struct Scratch(std::path::PathBuf);

impl Scratch {
    fn create(path: &std::path::Path) -> Result<Scratch> {
        std::fs::create_dir(path).with_context(|| {
            format!(
                "creating the NIRC frame bench's scratch folder {} (it must not exist)",
                path.display()
            )
        })?;
        Ok(Scratch(path.to_path_buf()))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if let Err(e) = std::fs::remove_dir_all(&self.0) {
            eprintln!(
                "warning: could not remove the NIRC frame bench's scratch folder {}: {e}",
                self.0.display()
            );
        }
    }
}

/// Plays `warmup` untimed and then `frames` timed frames per predictor at `resolution`; the run
/// folders go under `scratch`, a folder this creates (it must not exist) and removes afterwards,
/// also on an error.
pub fn run(
    resolution: (u32, u32),
    warmup: u32,
    frames: u32,
    scratch: &std::path::Path,
) -> Result<Table1> {
    anyhow::ensure!(frames > 0, "the NIRC frame bench needs at least 1 timed frame");
    let guard = Scratch::create(scratch)?;
    let mut worlds = Vec::new();
    for predictor in PREDICTORS {
        eprintln!(
            "bench: NIRC frames, building the {predictor} world ({}x{})",
            resolution.0, resolution.1
        );
        let origin = scratch.join(format!("{predictor}.ron"));
        let scenario =
            Scenario::from_ron(&scenario_text(resolution, warmup, frames, predictor), &origin)?;
        let folder = RunFolder::new(scratch.join(predictor));
        let spec = RunSpec::from_scenario(
            scenario,
            &Overrides { out: Some(folder.root.clone()), ..Default::default() },
        )?;
        let gpu = Gpu::new()?;
        let world = FrameWorld::build(
            &spec,
            gpu,
            scratch.join("references"),
            folder.clone(),
            ProgressBar::hidden(),
        )?;
        folder.prepare()?;
        worlds.push(world);
    }
    for step in 0..warmup + frames {
        for &i in &ORDERS[step as usize % ORDERS.len()] {
            worlds[i].run_frame(step, warmup).with_context(|| {
                format!("NIRC frame bench, {} world, frame {step}", PREDICTORS[i])
            })?;
        }
    }
    let mut rows = Vec::new();
    for (predictor, world) in PREDICTORS.iter().zip(&mut worlds) {
        let records = std::mem::take(&mut world.world.resource_mut::<RunOutput>().records);
        anyhow::ensure!(
            records.len() == frames as usize,
            "the {predictor} world recorded {} frames, expected {frames}",
            records.len()
        );
        let frame_ms = records
            .iter()
            .map(|r| {
                r.passes_total_ms().with_context(|| {
                    format!("the {predictor} world's frame {} has an untimed pass", r.frame)
                })
            })
            .collect::<Result<Vec<f64>>>()?;
        let pass_mean = |name: &str| {
            mean(
                &records
                    .iter()
                    .filter_map(|r| r.passes.iter().find(|(p, _)| p == name).and_then(|(_, t)| *t))
                    .collect::<Vec<f64>>(),
            )
        };
        let pass_ms: Vec<(String, f64)> =
            records[0].passes.iter().map(|(p, _)| (p.clone(), pass_mean(p))).collect();
        rows.push(FrameTimes {
            predictor: predictor.to_string(),
            ms_per_frame: mean(&frame_ms),
            infer_ms: pass_mean("nirc_infer"),
            pass_ms,
            frame_ms,
        });
    }
    drop(worlds);
    drop(guard);
    Ok(table(resolution, warmup, frames, rows))
}

/// Table 1 from its rows (High-LR only, EMA-only, blend). Frame k of each world ran in the same
/// round, so the blend's and EMA-only's frames are paired.
fn table(resolution: (u32, u32), warmup: u32, frames: u32, rows: Vec<FrameTimes>) -> Table1 {
    let (ema, blend) = (&rows[1], &rows[2]);
    let percent = |ms: f64| 100.0 * ms / ema.ms_per_frame;
    let diffs: Vec<f64> = blend.frame_ms.iter().zip(&ema.frame_ms).map(|(b, e)| b - e).collect();
    let s = Sample::of(&diffs);
    let d = s.mean;
    let half = if s.n > 1 {
        tools::suite::student_t::quantile(0.975, (s.n - 1) as f64) * s.standard_error()
    } else {
        f64::NAN
    };
    Table1 {
        scene: "cornell_box".into(),
        resolution,
        warmup_frames: warmup,
        timed_frames: frames,
        blend_overhead_frame_percent: percent(d),
        blend_overhead_frame_percent_ci95: (percent(d - half), percent(d + half)),
        blend_infer_extra_frame_percent: percent(blend.infer_ms - ema.infer_ms),
        rows,
    }
}

/// The mean (NaN for no values).
fn mean(v: &[f64]) -> f64 {
    Sample::of(v).mean
}

/// The table as Markdown: ms and FPS per predictor, as the paper prints them.
pub fn markdown(t: &Table1) -> String {
    let mut s = format!(
        "Whole NIRC frames, {} at {}x{}, {} timed frames after {} untimed (Table 1 of the paper)\n\n| predictor | ms / frame | FPS | its inference (ms) |\n|---|---:|---:|---:|\n",
        t.scene, t.resolution.0, t.resolution.1, t.timed_frames, t.warmup_frames
    );
    for r in &t.rows {
        s.push_str(&format!(
            "| {} | {:.2} | {:.2} | {:.2} |\n",
            r.predictor,
            r.ms_per_frame,
            1e3 / r.ms_per_frame,
            r.infer_ms
        ));
    }
    let (lo, hi) = t.blend_overhead_frame_percent_ci95;
    s.push_str(&format!(
        "\nblend overhead, % of EMA-only's whole frame: {:.1} (95% interval {lo:.1} to {hi:.1}); its inference pass alone: {:.1}\n\n| pass (ms) |",
        t.blend_overhead_frame_percent, t.blend_infer_extra_frame_percent
    ));
    for r in &t.rows {
        s.push_str(&format!(" {} |", r.predictor));
    }
    s.push_str(&format!("\n|---|{}\n", "---:|".repeat(t.rows.len())));
    for (i, (pass, _)) in t.rows[0].pass_ms.iter().enumerate() {
        s.push_str(&format!("| {pass} |"));
        for r in &t.rows {
            let ms = r.pass_ms.get(i).filter(|(p, _)| p == pass).map_or(f64::NAN, |(_, ms)| *ms);
            s.push_str(&format!(" {ms:.2} |"));
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(predictor: &str, frame_ms: &[f64], infer_ms: f64) -> FrameTimes {
        FrameTimes {
            predictor: predictor.into(),
            ms_per_frame: mean(frame_ms),
            infer_ms,
            pass_ms: vec![("nirc_infer".into(), infer_ms)],
            frame_ms: frame_ms.to_vec(),
        }
    }

    #[test]
    fn overhead_is_the_mean_paired_difference_with_its_t_interval() {
        // Differences 4, 6, 5 ms over EMA-only's mean frame of 100 ms: mean 5%, sd 1 ms,
        // half-width t(0.975, 2) / sqrt(3) = 4.3027 / 1.7321 = 2.4841 ms.
        let rows = vec![
            row("HighLrOnly", &[90.0, 90.0, 90.0], 10.0),
            row("EmaOnly", &[98.0, 102.0, 100.0], 10.0),
            row("Blend", &[102.0, 108.0, 105.0], 13.0),
        ];
        let t = table((8, 8), 1, 3, rows);
        assert!((t.blend_overhead_frame_percent - 5.0).abs() < 1e-12);
        let (lo, hi) = t.blend_overhead_frame_percent_ci95;
        assert!(
            (lo - (5.0 - 2.4841)).abs() < 1e-3 && (hi - (5.0 + 2.4841)).abs() < 1e-3,
            "{lo} {hi}"
        );
        assert!((t.blend_infer_extra_frame_percent - 3.0).abs() < 1e-12);
        // One frame: no interval.
        let t = table(
            (8, 8),
            1,
            1,
            vec![
                row("HighLrOnly", &[90.0], 1.0),
                row("EmaOnly", &[100.0], 1.0),
                row("Blend", &[104.0], 2.0),
            ],
        );
        assert!(
            (t.blend_overhead_frame_percent - 4.0).abs() < 1e-12
                && t.blend_overhead_frame_percent_ci95.0.is_nan()
        );
    }
}
