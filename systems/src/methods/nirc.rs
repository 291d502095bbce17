//! Path tracing terminated into the neural incident radiance cache (reliability-weighted NIRC,
//! ../shared/seeds/reliability-weighted-nirc.txt). The cache, its camera paths and its training
//! are shared by every NIRC method of a run with the same cache settings (`SharedCache`): as in
//! the paper, EMA-only, High-LR, blend and switch see identical training and identical path
//! samples, and differ only in how queries are answered. Per frame, whichever of them renders
//! first does the shared work:
//!
//! 1. camera paths up to the termination vertex -> queries       (`nirc_paths`)
//! 2. per predictor mode: cache inference + resolve into an image (`nirc_infer`)
//! 3. training records from a seeded subset of the queries + one training step (`nirc_train`)
//!
//! Inference uses the cache as trained up to the previous frame (NRC's order). Pass times are
//! wall times of each submission to completion (nothing else runs on the device meanwhile);
//! a method's frame time is paths + its own inference + training.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::PathBuf;
use std::rc::{Rc, Weak};
use std::time::Instant;

use anyhow::{Context, Result};
use nirc::{CacheOutput, CachePathSettings, CachePaths, NeuralCache, NircConfig, PredictorMode, SceneBounds};
use render::gpu::Gpu;
use render::path_tracer::PathTracer;
use render::scene::SceneDesc;
use sha2::{Digest, Sha256};
use sim::Scenario;

use super::{FrameContext, FrameMethod, MethodImage, MethodOutput};

/// What one shared cache is keyed by within a run.
#[derive(Clone, Debug, PartialEq)]
pub struct NircSettings {
    pub spp: u32,
    pub cache: NircConfig,
    pub paths: CachePathSettings,
    pub pretrain_frames: u32,
}

/// One frame's result for one predictor mode.
#[derive(Clone, Default)]
struct ModeFrame {
    radiance: Vec<[f32; 4]>,
    /// Per pixel mean σ (weight of High-LR) and answered samples.
    sigma: Vec<[f32; 4]>,
    infer_ms: f64,
}

struct Gpuside {
    paths: CachePaths,
    cache: NeuralCache,
    outputs: Vec<(PredictorMode, CacheOutput)>,
    diagnostics: CacheOutput,
}

/// Cache, paths and per-frame results shared by the NIRC methods of one run.
pub struct SharedCache {
    settings: NircSettings,
    modes: Vec<PredictorMode>,
    gpu: Option<Gpuside>,
    frame: Option<u32>,
    results: HashMap<PredictorMode, ModeFrame>,
    paths_ms: f64,
    train_ms: f64,
    stats: Vec<(String, f64)>,
    /// Motion vectors of the frame's pixel-centre primary hits (shared by every mode).
    motion: Vec<[f32; 2]>,
    /// Rays traced this frame: camera paths (with motion rays), training targets.
    rays: [u64; 2],
    /// Camera paths shaded this frame (pixels x spp).
    shaded: u64,
    warm_start: Option<PathBuf>,
}

thread_local! {
    /// Shared caches of the methods alive on this thread, by (scenario, settings). Weak: a
    /// run's caches go away with its methods.
    static SHARED: RefCell<Vec<(String, Weak<RefCell<SharedCache>>)>> = const { RefCell::new(Vec::new()) };
}

fn shared_for(scenario: &Scenario, settings: &NircSettings, mode: PredictorMode) -> Rc<RefCell<SharedCache>> {
    let key = format!(
        "{}|{}|{}|{}|{}",
        scenario.origin.display(),
        scenario.name,
        settings.spp,
        serde_json::to_string(&(&settings.cache, &settings.paths)).expect("settings serialise"),
        settings.pretrain_frames
    );
    SHARED.with(|s| {
        let mut list = s.borrow_mut();
        list.retain(|(_, w)| w.strong_count() > 0);
        let found = list.iter().find(|(k, _)| *k == key).and_then(|(_, w)| w.upgrade());
        let shared = found.unwrap_or_else(|| {
            let rc = Rc::new(RefCell::new(SharedCache {
                settings: settings.clone(),
                modes: Vec::new(),
                gpu: None,
                frame: None,
                results: HashMap::new(),
                paths_ms: 0.0,
                train_ms: 0.0,
                stats: Vec::new(),
                motion: Vec::new(),
                rays: [0; 2],
                shaded: 0,
                warm_start: None,
            }));
            list.push((key, Rc::downgrade(&rc)));
            rc
        });
        if !shared.borrow().modes.contains(&mode) {
            shared.borrow_mut().modes.push(mode);
        }
        shared
    })
}

fn wait(gpu: &Gpu) -> Result<()> {
    nirc::gpu::readback::wait_idle(gpu)?;
    Ok(())
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// Scene bounds of the cache's grids, padded a little so that points on the box faces stay
/// inside.
fn scene_bounds(tracer: &PathTracer) -> SceneBounds {
    let (lo, hi) = tracer.geometry().bounds();
    let pad = (hi - lo).max_element().max(1e-3) * 1e-3;
    SceneBounds::new((lo - pad).to_array(), (hi + pad).to_array())
}

impl SharedCache {
    /// Key of a warm start: everything that affects the pre-trained state.
    fn warm_start_key(&self, gpu: &Gpu, scene: &SceneDesc, scenario: &Scenario, tracer: &PathTracer) -> String {
        let mut h = Sha256::new();
        h.update(format!("{scene:?}").as_bytes());
        h.update(serde_json::to_string(&(&self.settings.cache, &self.settings.paths)).unwrap().as_bytes());
        h.update(format!("{:?}|{}|{}|{}", tracer.settings(), self.settings.spp, self.settings.pretrain_frames, scenario.seed).as_bytes());
        h.update(CachePaths::shader_source().as_bytes());
        h.update(nirc::gpu::shaders::all_sources().as_bytes());
        h.update(gpu.summary.to_string().as_bytes());
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    fn init(&mut self, ctx: &FrameContext) -> Result<()> {
        let gpu = ctx.gpu;
        let paths = CachePaths::new(gpu, ctx.tracer, self.settings.spp, self.settings.paths.clone())?;
        let bounds = scene_bounds(ctx.tracer);
        let mut cache_config = self.settings.cache.clone();
        cache_config.max_batch = cache_config.max_batch.max(paths.record_count());
        let mut cache = None;
        if self.settings.pretrain_frames > 0 {
            let dir = ctx.cache_dir.join("nirc");
            let file = dir.join(format!("{}.nirc", self.warm_start_key(gpu, ctx.scene, ctx.scenario, ctx.tracer)));
            if file.exists() {
                cache = Some(NeuralCache::load(gpu, &file).with_context(|| format!("loading the NIRC warm start {}", file.display()))?);
            } else {
                let fresh = NeuralCache::new(gpu, &cache_config, bounds)?;
                for k in 0..self.settings.pretrain_frames {
                    // Frame numbers of their own, so pre-training samples differ from the run's.
                    let frame = u32::MAX - k;
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    paths.encode_queries(gpu, &mut encoder, ctx.tracer, ctx.scenario.seed, frame);
                    paths.encode_records(gpu, &mut encoder, ctx.tracer);
                    fresh.encode_train(gpu, &mut encoder, paths.records(), paths.record_count())?;
                    gpu.queue.submit([encoder.finish()]);
                    wait(gpu)?;
                }
                std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
                let tmp = file.with_extension("tmp");
                fresh.save(gpu, &tmp)?;
                std::fs::rename(&tmp, &file).with_context(|| format!("writing {}", file.display()))?;
                cache = Some(fresh);
            }
            self.warm_start = Some(file);
        }
        let cache = match cache {
            Some(c) => c,
            None => NeuralCache::new(gpu, &cache_config, bounds)?,
        };
        let mut outputs = Vec::new();
        for &m in &self.modes {
            outputs.push((m, paths.output(gpu)?));
        }
        let diagnostics = paths.output(gpu)?;
        self.gpu = Some(Gpuside { paths, cache, outputs, diagnostics });
        Ok(())
    }

    /// The shared work of frame `ctx.frame`: paths, inference of every mode, training.
    fn render_frame(&mut self, ctx: &FrameContext) -> Result<()> {
        if self.gpu.is_none() {
            self.init(ctx)?;
        }
        let g = self.gpu.as_ref().expect("initialised");
        let gpu = ctx.gpu;
        let tracer = &*ctx.tracer;

        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        g.paths.encode_queries(gpu, &mut encoder, tracer, ctx.scenario.seed, ctx.frame);
        gpu.queue.submit([encoder.finish()]);
        wait(gpu)?;
        self.paths_ms = ms(start);
        self.motion = g.paths.read_motion(gpu)?;

        self.results.clear();
        for (mode, out) in &g.outputs {
            let start = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            g.cache.encode_infer(gpu, &mut encoder, g.paths.queries(), g.paths.query_count(), &out.answers, *mode)?;
            g.paths.encode_resolve(gpu, &mut encoder, tracer, out);
            gpu.queue.submit([encoder.finish()]);
            wait(gpu)?;
            let infer_ms = ms(start);
            let (radiance, sigma) = g.paths.read_image(gpu, out)?;
            self.results.insert(*mode, ModeFrame { radiance, sigma, infer_ms });
        }

        // Reliability at this frame's queries, before the frame's training step.
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        g.cache.encode_reliability(gpu, &mut encoder, g.paths.queries(), g.paths.query_count(), &g.diagnostics.answers)?;
        gpu.queue.submit([encoder.finish()]);
        let diag = g.paths.read_answers(gpu, &g.diagnostics)?;
        let valid = g.paths.read_query_valid(gpu)?;

        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        g.paths.encode_records(gpu, &mut encoder, tracer);
        g.cache.encode_train(gpu, &mut encoder, g.paths.records(), g.paths.record_count())?;
        gpu.queue.submit([encoder.finish()]);
        wait(gpu)?;
        self.train_ms = ms(start);
        self.rays = g.paths.read_rays(gpu)?;
        self.shaded = g.paths.query_count() as u64;

        let counters = g.cache.counters(gpu)?;
        let loss = g.cache.last_loss(gpu, g.paths.record_count())?;
        self.stats = reliability_stats(&diag, &valid);
        self.stats.push(("train_loss".into(), loss));
        self.stats.push(("rejected_steps".into(), counters.rejected_steps as f64));
        self.frame = Some(ctx.frame);
        Ok(())
    }
}

/// Means over the frame's answered queries of r̄_cur, r̄_EMA, the blend's σ, and the share of
/// queries whose cell prefers High-LR (σ > 0.5); σ is 0 during the grid's warm-up.
fn reliability_stats(diag: &[[f32; 4]], valid: &[bool]) -> Vec<(String, f64)> {
    let (mut n, mut r_cur, mut r_ema, mut sigma, mut prefer) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (d, &v) in diag.iter().zip(valid) {
        if !v || !d.iter().all(|x| x.is_finite()) {
            continue;
        }
        n += 1.0;
        r_cur += d[0] as f64;
        r_ema += d[1] as f64;
        sigma += d[2] as f64;
        prefer += (d[2] > 0.5) as u32 as f64;
    }
    let n = f64::max(n, 1.0);
    vec![
        ("reliability_high_lr".into(), r_cur / n),
        ("reliability_ema".into(), r_ema / n),
        ("blend_sigma".into(), sigma / n),
        ("prefer_high_lr".into(), prefer / n),
    ]
}

/// Figure 3's colours: green where High-LR is preferred (σ), red where EMA is (1 - σ); black
/// where no query was answered.
pub fn preference_map(sigma: &[[f32; 4]]) -> Vec<[f32; 4]> {
    sigma.iter().map(|s| if s[3] > 0.0 { [1.0 - s[0], s[0], 0.0, 1.0] } else { [0.0, 0.0, 0.0, 1.0] }).collect()
}

pub struct Nirc {
    spp: u32,
    mode: PredictorMode,
    shared: Rc<RefCell<SharedCache>>,
}

impl Nirc {
    pub fn new(scenario: &Scenario, settings: NircSettings, mode: PredictorMode) -> Result<Self> {
        settings.cache.validate()?;
        Ok(Self { spp: settings.spp, mode, shared: shared_for(scenario, &settings, mode) })
    }

    /// The warm-start file this method's cache was loaded from or saved to, if any.
    pub fn warm_start(&self) -> Option<PathBuf> {
        self.shared.borrow().warm_start.clone()
    }
}

impl FrameMethod for Nirc {
    fn label(&self) -> String {
        format!("nirc_{}_{}spp", sim::scenario::predictor_label(self.mode), self.spp)
    }

    fn spp(&self) -> u32 {
        self.spp
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput> {
        let mut shared = self.shared.borrow_mut();
        if shared.frame != Some(ctx.frame) {
            shared.render_frame(ctx)?;
        }
        let r = shared.results.get(&self.mode).cloned().context("this predictor mode was not rendered")?;
        let mut stats = shared.stats.clone();
        stats.push(("nirc_ms".into(), shared.paths_ms + r.infer_ms + shared.train_ms));
        let mut images = Vec::new();
        if matches!(self.mode, PredictorMode::Blend | PredictorMode::Switch) {
            images.push(MethodImage { name: "preference".into(), pixels: preference_map(&r.sigma), hdr: false });
        }
        Ok(MethodOutput {
            radiance: r.radiance,
            motion: shared.motion.clone(),
            passes: vec![
                ("nirc_paths".into(), Some(shared.paths_ms)),
                ("nirc_infer".into(), Some(r.infer_ms)),
                ("nirc_train".into(), Some(shared.train_ms)),
            ],
            stats,
            images,
            // Each submission timed alone to completion (nothing else runs on the device).
            clock: Some(render::timing::Clock::Wall),
            // Camera paths and training paths (shared by the modes: each pays them once).
            rays: Some(shared.rays[0] + shared.rays[1]),
            shaded: Some(shared.shaded),
        })
    }
}
