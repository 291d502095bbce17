//! The relations section 4 of reliability-weighted-nirc.txt reports, played end to end through
//! `flicker run`'s playback at a tiny size (32x18, a 1-hidden-layer width-32 cache, 512 records
//! per frame, reliability warm-up K = 16): relations between methods, not numbers.
//!
//! - After the light turns, the blend's FLIP is below EMA-only's; before it, the blend's SMAPE
//!   is below High-LR's.
//! - With the scene static, both predictors' mean reliability rises after warm-up, and after a
//!   long pre-training EMA is the more reliable predictor.
//!
//! Each relation holds over three seeds: the one-sided 95% bound (Student t, 2 degrees of
//! freedom) of the mean per-seed difference must lie on the right side of zero, so the margin
//! comes from the spread across seeds.

use std::path::{Path, PathBuf};

use frame::frame_record::FrameRecord;
use playback::play::{Overrides, RunOptions, run};

use testkit::relations::assert_positive;

const CACHE: &str = "cache: (
            encoding: (levels: 8, features_per_level: 2, log2_table_size: 12, base_resolution: 4, growth_factor: 1.5),
            network: (width: 32, hidden_layers: 1),
            reliability: (resolution: 16, log2_cells: 12, warmup: 16),
            max_batch: 512,
        ),
        paths: (termination_vertex: 1, train_records: 512)";

const SEEDS: [u64; 3] = [3, 4, 5];

fn scenario(
    dir: &Path,
    name: &str,
    seed: u64,
    frames: u32,
    warmup: u32,
    pretrain: u32,
    events: &str,
    reference: bool,
) -> PathBuf {
    // The Cornell box: its only light is an emissive quad. Its direct light is NEE's at the
    // termination vertex; the cache holds the indirect light (colour bleeding), which a light
    // change reaches through the targets (see cache_paths.wgsl).
    let methods: Vec<String> = ["EmaOnly", "HighLrOnly", "Blend"]
        .iter()
        .map(|p| format!("Nirc(spp: 1, predictor: {p}, pretrain_frames: {pretrain}, {CACHE})"))
        .collect();
    let reference =
        if reference { "(spp: 64, frames: Every(1))" } else { "(spp: 64, frames: None)" };
    let text = format!(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: {frames}, warmup_frames: {warmup}, seed: {seed}, max_depth: 3,
    methods: [{}], reference: {reference}, events: [{events}])",
        methods.join(", ")
    );
    let path = dir.join(format!("{name}.ron"));
    std::fs::write(&path, text).unwrap();
    path
}

fn play(
    name: &str,
    seed: u64,
    frames: u32,
    warmup: u32,
    pretrain: u32,
    events: &str,
    reference: bool,
) -> Vec<FrameRecord> {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let file = scenario(&dir, name, seed, frames, warmup, pretrain, events, reference);
    let opts = RunOptions {
        scenario: file,
        overrides: Overrides { out: Some(dir.join("run")), ..Default::default() },
        cache_dir: Some(dir.join("references")),
        progress: false,
    };
    let summary = run(&opts).expect("run");
    summary.records
}

fn series(
    records: &[FrameRecord],
    method: &str,
    f: impl Fn(&FrameRecord) -> Option<f64>,
) -> Vec<f64> {
    let mut rows: Vec<&FrameRecord> = records.iter().filter(|r| r.method == method).collect();
    rows.sort_by_key(|r| r.frame);
    // NaN where a frame has no value (SMAPE of the first frame).
    rows.iter().map(|r| f(r).unwrap_or(f64::NAN)).collect()
}

fn stat(r: &FrameRecord, name: &str) -> Option<f64> {
    r.stats.iter().find(|(k, _)| k == name).map(|s| s.1)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

const EMA: &str = "nirc_ema_1spp";
const HIGH_LR: &str = "nirc_highlr_1spp";
const BLEND: &str = "nirc_blend_1spp";

#[test]
fn blend_adapts_faster_than_ema_and_flickers_less_than_high_lr() {
    // 30 warm-up frames (training, past the reliability warm-up), then 16 recorded frames; the
    // ceiling light is lowered and tilted towards the green wall at simulation frame 36 =
    // recorded frame 6.
    let events = "(frame: 36, action: MoveBy(entity: \"ceiling_light\", offset: (0.0, -0.3, 0.0))), (frame: 36, action: Rotate(entity: \"ceiling_light\", axis: (0.0, 0.0, 1.0), degrees: 60.0))";
    let (mut adapt, mut steady) = (Vec::new(), Vec::new());
    for seed in SEEDS {
        let records = play("light_change", seed, 16, 30, 0, events, true);
        let flip = |m: &str| series(&records, m, |r| r.flip);
        let smape = |m: &str| series(&records, m, |r| r.smape);
        // Frames 3..=8 after the change (recorded 9..=14).
        let after = 9..15;
        adapt.push(mean(&flip(EMA)[after.clone()]) - mean(&flip(BLEND)[after]));
        // Steady state before the change (SMAPE of recorded frames 1..=5 against their previous).
        let before = 1..6;
        steady.push(mean(&smape(HIGH_LR)[before.clone()]) - mean(&smape(BLEND)[before]));
    }
    assert_positive("FLIP after the change, EMA-only minus blend", &adapt);
    assert_positive("SMAPE before the change, High-LR minus blend", &steady);
}

#[test]
fn static_scene_reliability_rises() {
    let mut rises = [Vec::new(), Vec::new()];
    for seed in SEEDS {
        let records = play("static", seed, 40, 0, 0, "", false);
        for (k, name) in ["reliability_ema", "reliability_high_lr"].iter().enumerate() {
            let r = series(&records, BLEND, |row| stat(row, name));
            // From an untrained cache (frames 1..5) to the end: the predictors learn the scene.
            rises[k].push(mean(&r[35..40]) - mean(&r[1..6]));
        }
    }
    assert_positive("reliability_ema, last 5 frames minus frames 1-5", &rises[0]);
    assert_positive("reliability_high_lr, last 5 frames minus frames 1-5", &rises[1]);
}

#[test]
fn static_scene_ema_is_the_more_reliable_predictor() {
    // The paper's steady state follows a long pre-training: here 300 training-only frames, so
    // that the EMA weights (horizon ~100 steps at alpha = 0.99) have caught up with the trained
    // weights. Before that the lagging EMA is no more reliable than High-LR (σ ~ 0.5).
    let mut margin = Vec::new();
    let mut below_half = Vec::new();
    for seed in SEEDS {
        let records = play("static_pretrained", seed, 40, 0, 300, "", false);
        let late = 20..40;
        let r_ema = series(&records, BLEND, |row| stat(row, "reliability_ema"));
        let r_hlr = series(&records, BLEND, |row| stat(row, "reliability_high_lr"));
        let sigma = series(&records, BLEND, |row| stat(row, "blend_sigma"));
        margin.push(mean(&r_ema[late.clone()]) - mean(&r_hlr[late.clone()]));
        below_half.push(0.5 - mean(&sigma[late]));
    }
    assert_positive("static scene: r̄ EMA minus r̄ High-LR", &margin);
    assert_positive("static scene: 0.5 minus the blend's mean σ", &below_half);
}
