//! Path tracing terminated into the neural incident radiance cache (reliability-weighted NIRC,
//! ../shared/seeds/reliability-weighted-nirc.txt). The cache, its camera paths and its training
//! are shared by every NIRC method of a run with the same cache settings (one [`NircCache`]
//! entity): as in the paper, EMA-only, High-LR, blend and switch see identical training and
//! identical path samples, and differ only in how queries are answered. Per frame:
//!
//! Render  `camera_paths`  camera paths up to the termination vertex -> queries, motion
//!         `infer`         per predictor mode: cache inference + resolve into an image
//! Learn   `reliability`   reliability grid at this frame's queries (before training)
//!         `train`         training records from a seeded subset of the queries, one Adam
//!                         step on the High-LR weights
//!         `ema`           the debiased EMA of the weights after the step
//!         `reliability_update`  the reliability grid's moments from the step's samples, the
//!                         step's commit, loss and rejected steps
//!         `frame_output`  each method's frame: image, motion, pass times, statistics
//!
//! Inference uses the cache as trained up to the previous frame (NRC's order). Pass times come
//! from render::timing::PassTimer (GPU timestamps where the adapter has them): nirc_paths,
//! nirc_infer and nirc_resolve (the method's own), nirc_records, nirc_train, nirc_ema and
//! nirc_reliability (shared: every mode reports them, as each would pay them alone).

use std::path::PathBuf;
use std::time::Instant;

use crate::config::ReliabilityStatistic;
use crate::gpu::train::{StepPart, TrainStep};
use crate::{
    CacheOutput, CachePathSettings, CachePaths, NeuralCache, NircCacheSettings, PredictorMode,
    SceneBounds,
};
use anyhow::{Context, Result, bail};
use bevy_ecs::error::BevyError;
use bevy_ecs::prelude::{Component, Entity, IntoScheduleConfigs, Query, Res, Schedule, World};
use render::gpu::Gpu;
use render::scene_gpu::SceneGpu;
use render::timing::{PassTimer, PassTiming};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, Run, Stage, failed};
use frame::{MethodImage, MethodOutput, MethodPlugin};

/// `Nirc(spp: 1, predictor: Blend, cache: (...), paths: (...), pretrain_frames: 0)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NircSettings {
    pub spp: u32,
    /// How queries are answered (inference only; training is the same for every mode).
    #[serde(default)]
    pub predictor: PredictorMode,
    #[serde(default)]
    pub cache: NircCacheSettings,
    #[serde(default)]
    pub paths: CachePathSettings,
    /// Training-only frames on the first frame's scene before anything renders (a warm start,
    /// saved next to the reference cache and reused).
    #[serde(default)]
    pub pretrain_frames: u32,
    /// TEST ONLY: never update the EMA weights, so that EMA-only (and the blend's EMA side)
    /// answer from the initial network. A deliberately broken method for the test that the
    /// smoke suite catches a regression (tools/tests/suite.rs); never set it in a scenario
    /// meant for results.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub test_skip_ema: bool,
}

impl NircSettings {
    pub fn label(&self) -> String {
        format!("nirc_{}_{}spp", predictor_label(self.predictor), self.spp)
    }

    /// Methods with equal keys share one cache: everything but the predictor.
    fn shared_key(&self) -> String {
        let key = format!(
            "{}|{}|{}",
            self.spp,
            serde_json::to_string(&(&self.cache, &self.paths)).expect("settings serialise"),
            self.pretrain_frames
        );
        // The test-only switch never shares a cache with a working method.
        if self.test_skip_ema { key + "|test_skip_ema" } else { key }
    }
}

/// Short name of a predictor mode in labels (`Fixed(0.5)` is `fixed50`).
pub fn predictor_label(mode: PredictorMode) -> String {
    match mode {
        PredictorMode::EmaOnly => "ema".into(),
        PredictorMode::HighLrOnly => "highlr".into(),
        PredictorMode::Blend => "blend".into(),
        PredictorMode::Switch => "switch".into(),
        PredictorMode::BlendBy(ReliabilityStatistic::Correlation) => "blend_corr".into(),
        PredictorMode::BlendBy(ReliabilityStatistic::RelativeError) => "blend_relerr".into(),
        PredictorMode::BlendBy(ReliabilityStatistic::ScaleRatio) => "blend_scale".into(),
        PredictorMode::Fixed(sigma) => format!("fixed{}", (sigma * 100.0).round()),
    }
}

/// One cache, its camera paths and training, shared by the NIRC methods of equal settings.
#[derive(Component)]
pub struct NircCache {
    key: String,
    settings: NircSettings,
    paths: CachePaths,
    cache: NeuralCache,
    /// One answer buffer per predictor mode in use, and one for the reliability diagnostics.
    outputs: Vec<(PredictorMode, CacheOutput)>,
    diagnostics: CacheOutput,
    paths_timer: PassTimer,
    infer_timer: PassTimer,
    train_timer: PassTimer,
    ema_timer: PassTimer,
    reliability_timer: PassTimer,
    paths_times: Vec<PassTiming>,
    /// nirc_records, nirc_train, nirc_ema, nirc_reliability of this frame.
    train_times: Vec<PassTiming>,
    /// This frame's training step, from `train` to `reliability_update`.
    step: Option<TrainStep>,
    stats: Vec<(String, f64)>,
    /// Motion vectors of the frame's pixel-centre primary hits (shared by every mode).
    motion: Vec<[f32; 2]>,
    /// Rays traced this frame: camera paths (with motion rays), training targets.
    rays: [u64; 2],
    /// Camera paths shaded this frame (pixels x spp).
    shaded: u64,
    /// The warm-start file the cache was loaded from or saved to, if any.
    pub warm_start: Option<PathBuf>,
    /// Wall time of the frame's training steps before the last (train_steps > 1).
    steps_wall_ms: Option<f64>,
}

/// One NIRC method: its predictor mode, its cache, and this frame's inference.
#[derive(Component)]
pub struct NircMethod {
    mode: PredictorMode,
    cache: Entity,
    inferred: Option<ModeFrame>,
}

/// One frame's result for one predictor mode.
#[derive(Clone, Default)]
struct ModeFrame {
    radiance: Vec<[f32; 4]>,
    /// Per pixel mean σ (weight of High-LR) and answered samples.
    sigma: Vec<[f32; 4]>,
    /// nirc_infer and nirc_resolve.
    times: Vec<PassTiming>,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = NircSettings;
    const NAME: &'static str = "Nirc";
    const MINIMAL_SETTINGS: &'static str = "(spp: 1)";
    const STATISTICS: &'static [frame::method::Statistic] = crate::recorded::STATISTICS;
    const CHARTS: &'static [frame::method::MethodChart] = crate::recorded::CHARTS;

    /// The blends and the switch write `preference` maps (σ per pixel; σ by region reads them).
    fn writes_image(settings: &NircSettings, name: &str) -> bool {
        name == "preference" && settings.predictor.has_preference_map()
    }

    fn label(settings: &NircSettings) -> String {
        settings.label()
    }

    fn spp(settings: &NircSettings) -> f64 {
        settings.spp as f64
    }

    fn temporal_window(_settings: &NircSettings) -> Option<f64> {
        None
    }

    fn set_spp(settings: &mut NircSettings, spp: u32) {
        settings.spp = spp;
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems((camera_paths, infer).chain().in_set(Stage::Render));
        schedule.add_systems(
            (reliability, train, ema, reliability_update, frame_output)
                .chain()
                .in_set(Stage::Learn),
        );
    }

    fn spawn(world: &mut World, entity: Entity, settings: &NircSettings) -> Result<()> {
        settings.cache.validate()?;
        if settings.spp == 0 {
            bail!("Nirc: spp 0; expected at least 1 path per pixel");
        }
        if let PredictorMode::Fixed(sigma) = settings.predictor
            && !(0.0..=1.0).contains(&sigma)
        {
            bail!(
                "Nirc: predictor Fixed({sigma}); expected a weight of the High-LR predictor in [0, 1]"
            );
        }
        let key = settings.shared_key();
        let existing = world
            .query::<(Entity, &NircCache)>()
            .iter(world)
            .find(|(_, c)| c.key == key)
            .map(|(e, _)| e);
        let cache = match existing {
            Some(e) => e,
            None => {
                let c = NircCache::build(world, settings, key)?;
                world.spawn(c).id()
            }
        };
        let c = world.get::<NircCache>(cache).expect("a cache entity");
        if !c.outputs.iter().any(|(m, _)| *m == settings.predictor) {
            let out = c.paths.output(&world.resource::<GpuDevice>().0)?;
            world
                .get_mut::<NircCache>(cache)
                .expect("a cache entity")
                .outputs
                .push((settings.predictor, out));
        }
        world.entity_mut(entity).insert(NircMethod {
            mode: settings.predictor,
            cache,
            inferred: None,
        });
        Ok(())
    }
}

fn wait(gpu: &Gpu) -> Result<()> {
    crate::gpu::readback::wait_idle(gpu)?;
    Ok(())
}

/// Scene bounds of the cache's grids, padded a little so that points on the box faces stay
/// inside.
fn scene_bounds(scene: &SceneGpu) -> SceneBounds {
    let (lo, hi) = scene.geometry().bounds();
    let pad = (hi - lo).max_element().max(1e-3) * 1e-3;
    SceneBounds::new((lo - pad).to_array(), (hi + pad).to_array())
}

impl NircCache {
    /// Key of a warm start: everything that affects the pre-trained state.
    fn warm_start_key(
        settings: &NircSettings,
        gpu: &Gpu,
        scene: &render::scene::SceneDesc,
        run: &Run,
        gpu_scene: &SceneGpu,
    ) -> String {
        let mut h = Sha256::new();
        h.update(format!("{scene:?}").as_bytes());
        h.update(serde_json::to_string(&(&settings.cache, &settings.paths)).unwrap().as_bytes());
        h.update(
            format!(
                "{:?}|{}|{}|{}",
                gpu_scene.settings(),
                settings.spp,
                settings.pretrain_frames,
                run.scenario.seed
            )
            .as_bytes(),
        );
        h.update(CachePaths::shader_source().as_bytes());
        h.update(crate::gpu::shaders::all_sources().as_bytes());
        h.update(gpu.summary.to_string().as_bytes());
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The cache on the first frame's scene: fresh, or pre-trained (loaded from the warm-start
    /// file when one exists, else trained and saved).
    fn build(world: &World, settings: &NircSettings, key: String) -> Result<Self> {
        let gpu = &world.resource::<GpuDevice>().0;
        let gpu_scene = &world.resource::<GpuScene>().0;
        let run = world.resource::<Run>();
        let scene = &world.resource::<sim::ExtractedScene>().scene;
        let paths = CachePaths::new(gpu, gpu_scene, settings.spp, settings.paths.clone())?;
        let bounds = scene_bounds(gpu_scene);
        let mut cache_config = settings.cache.clone();
        cache_config.max_batch = cache_config.max_batch.max(paths.record_count());
        let mut cache = None;
        let mut warm_start = None;
        if settings.pretrain_frames > 0 {
            let dir = run.cache_dir.join("nirc");
            let file = dir.join(format!(
                "{}.nirc",
                Self::warm_start_key(settings, gpu, scene, run, gpu_scene)
            ));
            if file.exists() {
                cache =
                    Some(NeuralCache::load(gpu, &file).with_context(|| {
                        format!("loading the NIRC warm start {}", file.display())
                    })?);
            } else {
                let fresh = NeuralCache::new(gpu, &cache_config, bounds)?;
                for k in 0..settings.pretrain_frames {
                    // Frame numbers of their own, so pre-training samples differ from the run's.
                    let frame = u32::MAX - k;
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    paths.encode_queries(gpu, &mut encoder, gpu_scene, run.scenario.seed, frame);
                    gpu.queue.submit([encoder.finish()]);
                    for step in 0..settings.paths.train_steps {
                        submit_step(
                            gpu,
                            gpu_scene,
                            &paths,
                            &fresh,
                            step_seed(run.scenario.seed, step),
                            frame,
                        )?;
                    }
                    wait(gpu)?;
                }
                std::fs::create_dir_all(&dir)
                    .with_context(|| format!("creating {}", dir.display()))?;
                let tmp = file.with_extension("tmp");
                fresh.save(gpu, &tmp)?;
                std::fs::rename(&tmp, &file)
                    .with_context(|| format!("writing {}", file.display()))?;
                cache = Some(fresh);
            }
            warm_start = Some(file);
        }
        let cache = match cache {
            Some(c) => c,
            None => NeuralCache::new(gpu, &cache_config, bounds)?,
        };
        let diagnostics = paths.output(gpu)?;
        Ok(Self {
            key,
            settings: settings.clone(),
            paths,
            cache,
            outputs: Vec::new(),
            diagnostics,
            paths_timer: PassTimer::new(gpu, &["nirc_paths"]),
            infer_timer: PassTimer::new(gpu, &["nirc_infer", "nirc_resolve"]),
            train_timer: PassTimer::new(gpu, &["nirc_records", "nirc_train"]),
            ema_timer: PassTimer::new(gpu, &["nirc_ema"]),
            reliability_timer: PassTimer::new(gpu, &["nirc_reliability"]),
            paths_times: Vec::new(),
            train_times: Vec::new(),
            step: None,
            stats: Vec::new(),
            motion: Vec::new(),
            rays: [0; 2],
            shaded: 0,
            warm_start,
            steps_wall_ms: None,
        })
    }

    /// The frame parameters of this cache's camera paths (set again by each system that traces or
    /// resolves: a training step of another seed may have written them in between).
    fn prepare(&self, gpu: &Gpu, scene: &SceneGpu, seed: u64, frame: u32) {
        self.paths.prepare(gpu, scene, seed, frame);
    }
}

fn frame_error(clock: &FrameClock) -> impl Fn(anyhow::Error) -> BevyError + '_ {
    move |e| failed(e.context(format!("NIRC frame {}", clock.global)))
}

/// Camera paths up to the termination vertex: the frame's cache queries and motion vectors.
pub fn camera_paths(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut NircCache>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for mut c in &mut caches {
        let c = &mut *c;
        let mut timed = c.paths_timer.begin(gpu, "nirc paths");
        c.paths
            .queries_timed(gpu, &mut timed, 0, &gpu_scene.0, run.scenario.seed, clock.global)
            .map_err(|e| err(e.into()))?;
        c.paths_times = timed.submit().map_err(|e| err(e.into()))?;
        c.motion = c.paths.read_motion(gpu).map_err(|e| err(e.into()))?;
    }
    Ok(())
}

/// Each method's inference (its predictor mode) and the resolve of its answers into an image.
pub fn infer(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    caches: Query<&NircCache>,
    mut methods: Query<(&mut NircMethod, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for (mut m, mut frame) in &mut methods {
        let start = Instant::now();
        let c = caches.get(m.cache).map_err(|e| err(anyhow::anyhow!("{e}")))?;
        let out = &c
            .outputs
            .iter()
            .find(|(mode, _)| *mode == m.mode)
            .ok_or_else(|| err(anyhow::anyhow!("predictor mode without answers")))?
            .1;
        c.prepare(gpu, &gpu_scene.0, run.scenario.seed, clock.global);
        let mut timed = c.infer_timer.begin(gpu, "nirc infer");
        c.cache
            .infer_timed(
                gpu,
                &mut timed,
                0,
                c.paths.queries(),
                c.paths.query_count(),
                &out.answers,
                m.mode,
            )
            .map_err(|e| err(e.into()))?;
        c.paths.resolve_timed(gpu, &mut timed, 1, &gpu_scene.0, out).map_err(|e| err(e.into()))?;
        let times = timed.submit().map_err(|e| err(e.into()))?;
        let (radiance, sigma) = c.paths.read_image(gpu, out).map_err(|e| err(e.into()))?;
        m.inferred = Some(ModeFrame { radiance, sigma, times });
        frame.add_cpu(start);
    }
    Ok(())
}

/// The reliability grid at this frame's queries, before the frame's training step: r̄_cur,
/// r̄_EMA, the blend's σ (frames.csv statistics, preference maps).
pub fn reliability(
    gpu: Res<GpuDevice>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut NircCache>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for mut c in &mut caches {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        c.cache
            .encode_reliability(
                gpu,
                &mut encoder,
                c.paths.queries(),
                c.paths.query_count(),
                &c.diagnostics.answers,
            )
            .map_err(|e| err(e.into()))?;
        gpu.queue.submit([encoder.finish()]);
        let diag = c.paths.read_answers(gpu, &c.diagnostics).map_err(|e| err(e.into()))?;
        let valid = c.paths.read_query_valid(gpu).map_err(|e| err(e.into()))?;
        c.stats = reliability_stats(&diag, &valid);
    }
    Ok(())
}

/// The seed of training step `step` of a frame (step 0 uses the run's seed, as with one step).
fn step_seed(seed: u64, step: u32) -> u64 {
    seed ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(step as u64)
}

/// One whole training step (records from the frame's queries, Adam, EMA, reliability, commit)
/// with `seed` for the record picks and targets, submitted untimed.
fn submit_step(
    gpu: &Gpu,
    scene: &SceneGpu,
    paths: &CachePaths,
    cache: &NeuralCache,
    seed: u64,
    frame: u32,
) -> Result<(), crate::NircError> {
    paths.prepare(gpu, scene, seed, frame);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    paths.encode_records(gpu, &mut encoder, scene);
    cache.encode_train(gpu, &mut encoder, paths.records(), paths.record_count())?;
    gpu.queue.submit([encoder.finish()]);
    Ok(())
}

/// Training records from the frame's paths and the Adam step of the High-LR weights. With
/// `train_steps` > 1 the earlier steps (records, Adam, EMA, reliability) run first, their wall
/// time in the statistic `nirc_steps_wall_ms`; the last step is split over this system, `ema` and
/// `reliability_update` as with one step.
pub fn train(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut NircCache>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for mut c in &mut caches {
        let c = &mut *c;
        let steps = c.settings.paths.train_steps;
        c.steps_wall_ms = None;
        if steps > 1 {
            let start = Instant::now();
            for step in 1..steps {
                submit_step(
                    gpu,
                    &gpu_scene.0,
                    &c.paths,
                    &c.cache,
                    step_seed(run.scenario.seed, step),
                    clock.global,
                )
                .map_err(|e| err(e.into()))?;
            }
            wait(gpu).map_err(&err)?;
            c.steps_wall_ms = Some(start.elapsed().as_secs_f64() * 1e3);
        }
        c.prepare(gpu, &gpu_scene.0, run.scenario.seed, clock.global);
        let mut timed = c.train_timer.begin(gpu, "nirc train");
        c.paths.records_timed(gpu, &mut timed, 0, &gpu_scene.0).map_err(|e| err(e.into()))?;
        c.step = c
            .cache
            .prepare_step(gpu, c.paths.records(), c.paths.record_count())
            .map_err(|e| err(e.into()))?;
        if let Some(step) = &c.step {
            c.cache.part_timed(&mut timed, 1, step, StepPart::Adam).map_err(|e| err(e.into()))?;
        }
        c.train_times = timed.submit().map_err(|e| err(e.into()))?;
        c.rays = c.paths.read_rays(gpu).map_err(|e| err(e.into()))?;
        c.shaded = c.paths.query_count() as u64;
    }
    Ok(())
}

/// The debiased EMA of the weights after this frame's Adam step (nothing on a rejected step).
pub fn ema(
    gpu: Res<GpuDevice>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut NircCache>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for mut c in &mut caches {
        let c = &mut *c;
        let Some(step) = &c.step else { continue };
        if c.settings.test_skip_ema {
            continue;
        }
        let mut timed = c.ema_timer.begin(gpu, "nirc ema");
        c.cache.part_timed(&mut timed, 0, step, StepPart::Ema).map_err(|e| err(e.into()))?;
        c.train_times.extend(timed.submit().map_err(|e| err(e.into()))?);
    }
    Ok(())
}

/// The reliability grid's moments from the step's samples and the step's commit; then the
/// step's loss and the count of rejected steps.
pub fn reliability_update(
    gpu: Res<GpuDevice>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut NircCache>,
) -> Result<(), BevyError> {
    let gpu = &gpu.0;
    let err = frame_error(&clock);
    for mut c in &mut caches {
        let c = &mut *c;
        if let Some(step) = c.step.take() {
            let mut timed = c.reliability_timer.begin(gpu, "nirc reliability");
            c.cache
                .part_timed(&mut timed, 0, &step, StepPart::Reliability)
                .map_err(|e| err(e.into()))?;
            c.train_times.extend(timed.submit().map_err(|e| err(e.into()))?);
        }
        let counters = c.cache.counters(gpu).map_err(|e| err(e.into()))?;
        let loss = c.cache.last_loss(gpu, c.paths.record_count()).map_err(|e| err(e.into()))?;
        c.stats.push(("train_loss".into(), loss));
        c.stats.push(("rejected_steps".into(), counters.rejected_steps as f64));
    }
    Ok(())
}

/// Each NIRC method's frame: its image, the shared motion, paths + its inference + training
/// times, the cache's statistics, and the preference map of blend and switch.
pub fn frame_output(
    caches: Query<&NircCache>,
    mut methods: Query<(&mut NircMethod, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut m, mut frame) in &mut methods {
        let c = caches.get(m.cache).map_err(|e| failed(anyhow::anyhow!("{e}")))?;
        let Some(r) = m.inferred.take() else { continue };
        let times: Vec<&PassTiming> =
            c.paths_times.iter().chain(&r.times).chain(&c.train_times).collect();
        let mut stats = c.stats.clone();
        stats.push((
            "nirc_ms".into(),
            times.iter().map(|t| t.ms).sum::<f64>() + c.steps_wall_ms.unwrap_or(0.0),
        ));
        if let Some(ms) = c.steps_wall_ms {
            stats.push(("nirc_steps_wall_ms".into(), ms));
        }
        // `blend_sigma` is the paper's blend's σ (shared); a blend by another statistic also
        // reports its own mean σ over the answered pixels.
        if let PredictorMode::BlendBy(_) = m.mode {
            stats.push(("own_sigma".into(), mean_answered_sigma(&r.sigma)));
        }
        let mut images = Vec::new();
        if m.mode.has_preference_map() {
            images.push(MethodImage {
                name: "preference".into(),
                pixels: preference_map(&r.sigma),
                hdr: false,
            });
        }
        frame.output = Some(MethodOutput {
            radiance: r.radiance,
            motion: c.motion.clone(),
            passes: times.iter().map(|t| (t.pass.clone(), Some(t.ms))).collect(),
            clock: times.first().map(|t| t.clock),
            stats,
            images,
            // Camera paths and training paths (shared by the modes: each pays them once).
            rays: Some(c.rays[0] + c.rays[1]),
            shaded: Some(c.shaded),
        });
    }
    Ok(())
}

/// Means over the frame's answered queries of r̄_cur, r̄_EMA, the blend's σ, and the share of
/// queries whose cell prefers High-LR (σ > 0.5); σ is 0 during the grid's warm-up. Also the
/// spread of what σ is a function of, d = r̄_cur − r̄_EMA (10th, 50th and 90th percentiles over
/// the queries, so over cells weighted by the pixels that see them), and the share of queries
/// whose σ is more than 0.1 from the even mixture (|d| > ln(1.5)/κ ≈ 0.1 at κ = 4): how much of
/// the image the reliability weighting actually moves.
fn reliability_stats(diag: &[[f32; 4]], valid: &[bool]) -> Vec<(String, f64)> {
    let (mut n, mut r_cur, mut r_ema, mut sigma, mut prefer, mut far) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut diff = Vec::new();
    for (d, &v) in diag.iter().zip(valid) {
        if !v || !d.iter().all(|x| x.is_finite()) {
            continue;
        }
        n += 1.0;
        r_cur += d[0] as f64;
        r_ema += d[1] as f64;
        sigma += d[2] as f64;
        prefer += (d[2] > 0.5) as u32 as f64;
        // During the warm-up (d[3] = 0) σ is 0 by rule, not by the statistics.
        if d[3] > 0.0 {
            far += ((d[2] - 0.5).abs() > 0.1) as u32 as f64;
            diff.push(d[0] as f64 - d[1] as f64);
        }
    }
    let n = f64::max(n, 1.0);
    let mut stats = vec![
        ("reliability_high_lr".into(), r_cur / n),
        ("reliability_ema".into(), r_ema / n),
        ("blend_sigma".into(), sigma / n),
        ("prefer_high_lr".into(), prefer / n),
    ];
    if !diff.is_empty() {
        diff.sort_by(f64::total_cmp);
        let quantile = |q: f64| diff[(q * (diff.len() - 1) as f64).round() as usize];
        stats.push(("reliability_diff_p10".into(), quantile(0.1)));
        stats.push(("reliability_diff_p50".into(), quantile(0.5)));
        stats.push(("reliability_diff_p90".into(), quantile(0.9)));
        stats.push(("sigma_far_from_even".into(), far / diff.len() as f64));
    }
    stats
}

/// Mean σ over the pixels that were answered (`.w` > 0), 0 if none.
fn mean_answered_sigma(sigma: &[[f32; 4]]) -> f64 {
    let answered: Vec<f64> = sigma.iter().filter(|s| s[3] > 0.0).map(|s| s[0] as f64).collect();
    answered.iter().sum::<f64>() / f64::max(answered.len() as f64, 1.0)
}

/// Figure 3's colours: green where High-LR is preferred (σ), red where EMA is (1 - σ); black
/// where no query was answered.
pub fn preference_map(sigma: &[[f32; 4]]) -> Vec<[f32; 4]> {
    sigma
        .iter()
        .map(|s| if s[3] > 0.0 { [1.0 - s[0], s[0], 0.0, 1.0] } else { [0.0, 0.0, 0.0, 1.0] })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_sigma_is_the_mean_over_answered_pixels() {
        let sigma = [[0.25, 0.0, 0.0, 1.0], [0.9, 0.0, 0.0, 0.0], [0.75, 0.0, 0.0, 1.0]];
        assert_eq!(mean_answered_sigma(&sigma), 0.5);
        assert_eq!(mean_answered_sigma(&[[0.9, 0.0, 0.0, 0.0]]), 0.0);
    }

    /// The spread of d = r̄_cur − r̄_EMA and the share of σ away from 0.5 count only answered
    /// queries past the grid's warm-up.
    #[test]
    fn reliability_stats_give_the_spread_of_the_difference_past_warm_up() {
        // (r̄_cur, r̄_EMA, σ, past warm-up)
        let mut diag: Vec<[f32; 4]> =
            (0..11).map(|i| [0.5 + 0.01 * i as f32, 0.5, 0.5, 1.0]).collect();
        diag[10][2] = 0.7; // one query far from the even mixture
        diag.push([0.9, 0.1, 0.0, 0.0]); // in warm-up: no difference counted
        diag.push([0.9, 0.1, 0.9, 1.0]); // not answered
        let mut valid = vec![true; diag.len()];
        *valid.last_mut().unwrap() = false;
        let stats = reliability_stats(&diag, &valid);
        let get = |k: &str| stats.iter().find(|s| s.0 == k).unwrap().1;
        assert!((get("reliability_diff_p10") - 0.01).abs() < 1e-6, "{stats:?}");
        assert!((get("reliability_diff_p50") - 0.05).abs() < 1e-6, "{stats:?}");
        assert!((get("reliability_diff_p90") - 0.09).abs() < 1e-6, "{stats:?}");
        assert!((get("sigma_far_from_even") - 1.0 / 11.0).abs() < 1e-9, "{stats:?}");
        // All in warm-up: the spread is not reported at all.
        let warm: Vec<[f32; 4]> = diag.iter().map(|d| [d[0], d[1], 0.0, 0.0]).collect();
        assert!(
            reliability_stats(&warm, &valid)
                .iter()
                .all(|s| !s.0.starts_with("reliability_diff") && s.0 != "sigma_far_from_even")
        );
    }
}
