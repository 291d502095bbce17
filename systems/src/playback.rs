//! `flicker run`: plays a scenario frame by frame, renders every method, the references it
//! asks for, measures, and records everything in a run folder.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use sim::{MethodSpec, Scenario, Simulation};

use crate::frame_record::{self, FrameRecord};
use crate::measure;
use crate::methods::{self, FrameContext, FrameMethod};
use crate::output;
use crate::reference_cache::{ReferenceCache, ReferenceKey};
use crate::run_folder::RunFolder;

/// Command-line overrides of the scenario's own settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub frames: Option<u32>,
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub out: Option<PathBuf>,
}

pub struct RunOptions {
    pub scenario: PathBuf,
    pub overrides: Overrides,
    /// Where references are cached; `None` for the default location.
    pub cache_dir: Option<PathBuf>,
    pub progress: bool,
}

/// What a finished run reports back.
pub struct RunSummary {
    pub folder: PathBuf,
    pub records: Vec<FrameRecord>,
    pub references_rendered: u32,
    pub references_cached: u32,
}

/// Loads the scenario and applies the overrides; every input error surfaces here, before
/// anything is written.
pub fn load_scenario(path: &Path, o: &Overrides) -> Result<Scenario> {
    let mut scenario = Scenario::load(path)?;
    if let Some(f) = o.frames {
        scenario.frames = f;
    }
    if let Some(r) = o.resolution {
        scenario.resolution = r;
    }
    if let Some(spp) = o.spp {
        for m in &mut scenario.methods {
            match m {
                MethodSpec::PathTracing { spp: s } => *s = spp,
                MethodSpec::Nirc { spp: s, .. } => *s = spp,
                MethodSpec::SampleCache { .. } => {}
                // 1 spp by construction.
                MethodSpec::Taa { .. } | MethodSpec::HashCache { .. } => {}
            }
        }
    }
    if let Some(s) = o.seed {
        scenario.seed = s;
    }
    if let Some(out) = &o.out {
        scenario.output = out.clone();
    }
    if scenario.frames == 0 {
        bail!("{}: frames must be at least 1", path.display());
    }
    if !(scenario.smape_epsilon.is_finite() && scenario.smape_epsilon >= 0.0) {
        bail!("{}: smape_epsilon must be a finite number >= 0, got {}", path.display(), scenario.smape_epsilon);
    }
    if scenario.methods.is_empty() {
        bail!("{}: no methods to run; add e.g. `methods: [PathTracing(spp: 1)]`", path.display());
    }
    Ok(scenario)
}

pub fn run(opts: &RunOptions) -> Result<RunSummary> {
    let scenario = load_scenario(&opts.scenario, &opts.overrides)?;
    let mut sim = Simulation::new(&scenario)?;
    let gpu = Gpu::new()?;
    let (width, height) = scenario.resolution;
    let settings = PathTracerSettings { width, height, max_depth: scenario.max_depth, rr_start_depth: 3 };
    let mut tracer = PathTracer::new(&gpu, sim.scene(), settings)
        .with_context(|| format!("{}: preparing the path tracer", opts.scenario.display()))?;

    let folder = RunFolder::new(&scenario.output);
    folder.prepare()?;
    let manifest = crate::manifest::build(&scenario, &opts.scenario, &gpu, &opts.overrides)?;
    output::write_json(&folder.manifest(), &manifest)?;

    let cache = ReferenceCache::new(opts.cache_dir.clone().unwrap_or_else(ReferenceCache::default_location));
    let mut methods: Vec<Box<dyn FrameMethod>> = Vec::new();
    for spec in &scenario.methods {
        let method = methods::build(spec, &gpu, &scenario, sim.scene())
            .with_context(|| format!("{}: preparing method {}", opts.scenario.display(), spec.label()))?;
        methods.push(method);
    }
    let bar = progress_bar(opts.progress, (scenario.warmup_frames + scenario.frames) as u64);

    // Warm-up frames are simulated and rendered (caches learn from them) but not recorded.
    for _ in 0..scenario.warmup_frames {
        bar.set_message("warm-up");
        tracer.update(&gpu, sim.scene());
        let frame = sim.frame();
        for method in &mut methods {
            let mut ctx = FrameContext { gpu: &gpu, tracer: &mut tracer, scene: sim.scene(), scenario: &scenario, frame, recorded: false, cache_dir: cache.dir() };
            method.render(&mut ctx).with_context(|| format!("{} warm-up frame {frame}", method.label()))?;
        }
        sim.step();
        bar.inc(1);
    }

    let mut records = Vec::new();
    let mut previous: Vec<Option<measure::Frame>> = vec![None; methods.len()];
    let (mut rendered, mut cached) = (0, 0);
    for frame in 0..scenario.frames {
        let global_frame = sim.frame();
        tracer.update(&gpu, sim.scene());

        let reference = if scenario.reference.wants(frame, scenario.frames) {
            let key = ReferenceCache::key(
                sim.scene(),
                &ReferenceKey {
                    width,
                    height,
                    spp: scenario.reference.spp,
                    seed: reference_seed(scenario.seed),
                    max_depth: scenario.max_depth,
                    rr_start_depth: settings.rr_start_depth,
                    adapter: &gpu.summary.to_string(),
                    shader_source: PathTracer::shader_source(),
                },
            );
            let pixels = match cache.load(&key, width, height) {
                Some(px) => {
                    cached += 1;
                    px
                }
                None => {
                    bar.set_message(format!("reference {frame:04}"));
                    let spp = scenario.reference.spp;
                    let px = tracer.render_reference(&gpu, spp, reference_seed(scenario.seed), global_frame, &mut |done, total| {
                        bar.set_message(format!("reference {frame:04}: {done}/{total} spp"));
                    })?;
                    cache.store(&key, width, height, &px)?;
                    rendered += 1;
                    px
                }
            };
            output::write_exr(&folder.reference(frame, "exr"), width, height, &pixels)?;
            output::write_png(&folder.reference(frame, "png"), width, height, &pixels, 1.0)?;
            Some(measure::Frame::from_radiance(width, height, &pixels, None))
        } else {
            None
        };

        for (m, method) in methods.iter_mut().enumerate() {
            let label = method.label();
            bar.set_message(format!("{label} frame {frame:04}"));
            let start = Instant::now();
            let mut ctx =
                FrameContext { gpu: &gpu, tracer: &mut tracer, scene: sim.scene(), scenario: &scenario, frame: global_frame, recorded: true, cache_dir: cache.dir() };
            let out = method.render(&mut ctx).with_context(|| format!("{label} frame {frame}"))?;
            let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
            output::write_exr(&folder.frame(&label, frame, "exr"), width, height, &out.radiance)?;
            output::write_png(&folder.frame(&label, frame, "png"), width, height, &out.radiance, 1.0)?;
            for image in &out.images {
                if image.hdr {
                    output::write_exr(&folder.method_image(&label, &image.name, frame, "exr"), width, height, &image.pixels)?;
                    output::write_png(&folder.method_image(&label, &image.name, frame, "png"), width, height, &image.pixels, 1.0)?;
                } else {
                    output::write_png_linear(&folder.method_image(&label, &image.name, frame, "png"), width, height, &image.pixels)?;
                }
            }
            let motion = (!out.motion.is_empty()).then_some(out.motion.as_slice());
            let current = measure::Frame::from_radiance(width, height, &out.radiance, motion);
            let mut record = measure::record(&current, previous[m].as_ref(), reference.as_ref(), &scenario);
            record.method = label;
            record.frame = frame;
            record.cpu_ms = cpu_ms;
            record.passes = out.passes;
            record.clock = out.clock;
            record.rays = out.rays;
            record.shaded = out.shaded;
            record.stats = out.stats;
            records.push(record);
            previous[m] = Some(current);
        }
        // Rewritten every frame so an interrupted run still has a complete table of what it did.
        output::write_text(&folder.frames_csv(), &frame_record::to_csv(&records))?;
        sim.step();
        bar.inc(1);
    }
    bar.finish_with_message("done");
    report::rebuild(&folder.root).with_context(|| format!("writing the report of {}", folder.root.display()))?;
    Ok(RunSummary { folder: folder.root, records, references_rendered: rendered, references_cached: cached })
}

/// References use their own random sequence, so they never share noise with a method.
fn reference_seed(seed: u64) -> u64 {
    seed ^ 0x5eed_0f_4e_fe_4e_9ce
}

fn progress_bar(enabled: bool, len: u64) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} frames  {elapsed_precise} elapsed, ETA {eta_precise}  {msg}")
            .expect("valid progress template"),
    );
    bar
}

