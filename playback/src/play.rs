//! `flicker run`: builds the frame's world and schedule from a scenario and runs the schedule
//! once per frame (frame); the run folder gets the images, frames.csv and the report.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use bevy_ecs::prelude::{Schedule, World};
use indicatif::{ProgressBar, ProgressStyle};
use render::gpu::Gpu;
use render::path_tracer::PathTracerSettings;
use render::scene_gpu::SceneGpu;
use sim::Simulation;

use crate::memory::{MethodMemory, RunMemory};
pub use crate::scenario::{Overrides, RunSpec};
use frame::frame_record::FrameRecord;
use frame::output;
use frame::reference_cache::ReferenceCache;
use frame::run_folder::RunFolder;
use frame::{
    self, FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Progress, References, Run,
    RunOutput,
};

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
    /// The run's report.html.
    pub report: PathBuf,
}

/// The frame's world of a scenario: the simulation's world with the run's resources, one
/// entity per method (GPU state built), and the schedule that plays a frame.
pub struct FrameWorld {
    pub world: World,
    pub schedule: Schedule,
}

/// A scenario with media refuses what would silently leave them out: methods that do not
/// render media, and more media than the volumetric path tracer (references, VolumePath) binds
/// (docs/methods/volume.md).
fn check_media_support(spec: &RunSpec, origin: &str) -> Result<()> {
    let scenario = &spec.scenario;
    if scenario.media.is_empty() {
        return Ok(());
    }
    for method in &spec.methods {
        let plugin = method.spec.plugin();
        if !plugin.sees_media() {
            anyhow::bail!(
                "{origin}:{}:{}: method {} does not render participating media and the scenario declares media ('{}'); expected only VolumePath or VolumeTransmittance methods in a scenario with media (docs/methods/volume.md)",
                method.entry.line,
                method.entry.column,
                method.label(),
                scenario.media[0].name
            );
        }
    }
    let references = (0..scenario.frames).any(|f| scenario.reference.wants(f, scenario.frames));
    let volume_path = spec.methods.iter().any(|m| m.spec.is::<volume::path::VolumePathSettings>());
    if let (Some(extra), true) =
        (scenario.media.get(media::gpu::MAX_MEDIA), references || volume_path)
    {
        anyhow::bail!(
            "{origin}: medium '{}': the volumetric path tracer (references, VolumePath) renders at most {} media; expected fewer, or more only with VolumeTransmittance methods and no references",
            extra.name,
            media::gpu::MAX_MEDIA
        );
    }
    Ok(())
}

impl FrameWorld {
    /// Everything a run needs before its first frame; input errors (names, sizes over the
    /// adapter's limits) surface here, before anything is written.
    pub fn build(
        spec: &RunSpec,
        gpu: Gpu,
        cache_dir: PathBuf,
        folder: RunFolder,
        progress: ProgressBar,
    ) -> Result<FrameWorld> {
        let scenario = &spec.scenario;
        let origin = scenario.origin.display().to_string();
        check_media_support(spec, &origin)?;
        let sim = Simulation::new(scenario)?;
        let (width, height) = scenario.resolution;
        let settings =
            PathTracerSettings { width, height, max_depth: scenario.max_depth, rr_start_depth: 3 };
        let mut ledger = render::memory::DeviceLedger::start(&gpu);
        // The device's faults become errors naming the step and the size (not wgpu's panic).
        let faults = gpu.catch_faults();
        let size = format!("{width}x{height}");
        let gpu_scene = SceneGpu::new(&gpu, sim.scene(), settings)
            .with_context(|| format!("{origin}: uploading the scene"))?;
        faults.check("uploading the scene", &size).with_context(|| origin.clone())?;
        let wants_references =
            (0..scenario.frames).any(|f| scenario.reference.wants(f, scenario.frames));
        let reference_renderer = wants_references
            .then(|| match scenario.reference.random_walk && scenario.media.is_empty() {
                true => frame::reference::ReferenceRenderer::random_walk(&gpu, &gpu_scene),
                false => frame::reference::ReferenceRenderer::new(
                    &gpu,
                    &gpu_scene,
                    !scenario.media.is_empty(),
                ),
            })
            .transpose()
            .with_context(|| format!("{origin}: preparing the reference renderer"))?;
        faults.check("preparing the reference renderer", &size).with_context(|| origin.clone())?;

        let mut world = sim.into_world();
        world.insert_resource(GpuDevice(gpu));
        world.insert_resource(GpuScene(gpu_scene));
        world.insert_resource(Run {
            scenario: scenario.clone(),
            width,
            height,
            cache_dir: cache_dir.clone(),
        });
        world.insert_resource(FrameClock::default());
        world.insert_resource(RunOutput { folder, records: Vec::new(), replay_until: 0 });
        world.insert_resource(References {
            cache: ReferenceCache::new(cache_dir),
            renderer: reference_renderer,
            current: None,
            rendered: 0,
            cached: 0,
        });
        world.insert_resource(Progress(progress));
        // The volumetric path tracer renders every declared medium (docs/methods/volume.md). More
        // than it binds pass check_media_support only without references and VolumePath, which
        // are all that use it.
        if !scenario.media.is_empty() && scenario.media.len() <= media::gpu::MAX_MEDIA {
            let gpu = &world.resource::<GpuDevice>().0;
            let medium = frame::scene_medium::SceneMedium::new(gpu, &scenario.media);
            world.insert_resource(medium);
            faults.check("uploading the media", &size).with_context(|| origin.clone())?;
        }
        frame::catch_failures(&mut world);
        let mut memory = RunMemory {
            scene_device_bytes: ledger.take(&world.resource::<GpuDevice>().0),
            ..Default::default()
        };

        for (index, method) in spec.methods.iter().enumerate() {
            let label = method.label();
            let entity = world
                .spawn((MethodInfo { index, label: label.clone() }, MethodFrame::default()))
                .id();
            let at = || format!("{origin}:{}:{}", method.entry.line, method.entry.column);
            method
                .spec
                .spawn(&mut world, entity)
                .with_context(|| format!("{}: preparing method {label}", at()))?;
            faults.check(&format!("preparing method {label}"), &size).with_context(at)?;
            let taken = ledger.take_buffers(&world.resource::<GpuDevice>().0);
            let (device_bytes, buffers) = taken.map_or((None, Vec::new()), |(d, b)| (Some(d), b));
            memory.methods.push(MethodMemory { label, device_bytes, buffers });
        }
        // The ledger's last count is the world as built: no second allocator report.
        memory.device_bytes_built = ledger.total();
        world.insert_resource(memory);
        world.insert_resource(frame::GpuFaults(faults));
        let schedule = crate::methods::schedule_for(&spec.methods);
        Ok(FrameWorld { world, schedule })
    }

    /// Plays one frame: `step` counts from 0 over warm-up and recorded frames.
    pub fn run_frame(&mut self, step: u32, warmup: u32) -> Result<()> {
        let recorded = step >= warmup;
        {
            let mut clock = self.world.resource_mut::<FrameClock>();
            clock.started = step > 0;
            clock.recorded = recorded;
            clock.frame = step.saturating_sub(warmup);
        }
        self.world.resource::<Progress>().0.set_message(if recorded {
            format!("frame {:04}", step - warmup)
        } else {
            "warm-up".into()
        });
        self.schedule.run(&mut self.world);
        // A fault of the last stage: the stages' own checks catch the earlier ones.
        let fault = self.world.resource::<frame::GpuFaults>().0.take();
        let owner = frame::last_owner().map_or(String::new(), |o| format!(", {o}"));
        match (frame::take_failure(), fault) {
            (Some(e), None) => Err(anyhow!("{e}")),
            (failure, Some(fault)) => {
                let run = self.world.resource::<Run>();
                let frame = step.saturating_sub(warmup);
                let then = failure.map_or(String::new(), |e| format!(" (then: {e})"));
                Err(anyhow!("frame {frame} at {}x{}{owner}: {fault}{then}", run.width, run.height))
            }
            (None, None) => Ok(()),
        }
    }
}

pub fn run(opts: &RunOptions) -> Result<RunSummary> {
    let spec = RunSpec::load(&opts.scenario, &opts.overrides)?;
    run_spec(&spec, opts)
}

/// [`run`] of a scenario already loaded, with `opts.overrides` applied (a suite keeps only some
/// of its methods first); `opts.scenario` names the file in the manifest.
pub fn run_spec(spec: &RunSpec, opts: &RunOptions) -> Result<RunSummary> {
    run_spec_on(spec, opts, Gpu::new()?)
}

/// [`run_spec`] on the caller's device (the fault tests': one with lower limits).
pub fn run_spec_on(spec: &RunSpec, opts: &RunOptions, gpu: Gpu) -> Result<RunSummary> {
    let manifest = crate::manifest::build(spec, &opts.scenario, &gpu, &opts.overrides)?;
    play(spec, gpu, manifest, opts.cache_dir.clone(), opts.progress, None)
}

/// Where a resumed run picks up (crate::resume): recorded frames below `from` are on disk; they
/// are played again, unwritten, to rebuild every method's state, and their frames.csv rows
/// must come out as `frames_csv` has them.
pub(crate) struct ResumeAt {
    pub from: u32,
    pub frames_csv: String,
}

/// Plays the run into `spec.scenario.output`, keeping manifest.json's status current: running,
/// then complete, or interrupted (a signal, after a whole frame) or failed, with the last
/// complete frame.
pub(crate) fn play(
    spec: &RunSpec,
    gpu: Gpu,
    mut manifest: serde_json::Value,
    cache_dir: Option<PathBuf>,
    progress: bool,
    resume: Option<ResumeAt>,
) -> Result<RunSummary> {
    use crate::manifest::{Status, set_status};
    let scenario = &spec.scenario;
    let folder = RunFolder::new(&scenario.output);
    let cache_dir = cache_dir.unwrap_or_else(ReferenceCache::default_location);
    let bar = progress_bar(progress, (scenario.warmup_frames + scenario.frames) as u64);
    let mut frames = FrameWorld::build(spec, gpu, cache_dir, folder.clone(), bar.clone())?;
    let from = resume.as_ref().map_or(0, |r| r.from);
    if resume.is_none() {
        folder.prepare()?;
    }
    let mut last_complete = from.checked_sub(1);
    set_status(&mut manifest, Status::Running, last_complete);
    output::write_json(&folder.manifest(), &manifest)?;
    frames.world.resource_mut::<RunOutput>().replay_until = from;

    // Warm-up frames are simulated and rendered (caches learn from them) but not recorded.
    let (warmup, total) = (scenario.warmup_frames, scenario.warmup_frames + scenario.frames);
    for step in 0..total {
        let stop = match frames.run_frame(step, warmup) {
            Err(e) => Some((Status::Failed, Some(e))),
            Ok(()) => {
                RunMemory::frame_played(&mut frames.world, step + 1);
                if let Some(frame) = step.checked_sub(warmup).filter(|f| *f >= from) {
                    last_complete = Some(frame);
                }
                let replayed =
                    resume.as_ref().filter(|r| r.from > 0 && step + 1 == warmup + r.from);
                match replayed.map(|r| replay_matches(&frames.world, r, &folder)) {
                    Some(Err(e)) => Some((Status::Failed, Some(e))),
                    _ if crate::interrupt::requested() && step + 1 < total => {
                        Some((Status::Interrupted, None))
                    }
                    _ => None,
                }
            }
        };
        if let Some((status, error)) = stop {
            bar.abandon();
            set_status(&mut manifest, status, last_complete);
            if let Some(e) = &error {
                manifest["error"] = format!("{e:#}").into();
            }
            output::write_json(&folder.manifest(), &manifest)?;
            // What it has: the summary and the page of the frames so far (marked incomplete).
            let report = report::rebuild(&folder.root, &crate::methods::registry::charts());
            return Err(match error {
                Some(e) => e,
                None => {
                    report.with_context(|| {
                        format!("writing the report of {}", folder.root.display())
                    })?;
                    crate::interrupt::Interrupted {
                        folder: folder.root.clone(),
                        last_complete_frame: last_complete,
                    }
                    .into()
                }
            });
        }
    }
    bar.finish_with_message("done");
    let world = &mut frames.world;
    RunMemory::finish(world, total);
    manifest["memory"] = serde_json::to_value(world.resource::<RunMemory>())?;
    set_status(&mut manifest, Status::Complete, last_complete);
    // The frames are all written; the report is not yet (a stop in between is resumable).
    let pending = folder.report_pending();
    std::fs::write(&pending, "").with_context(|| format!("writing {}", pending.display()))?;
    output::write_json(&folder.manifest(), &manifest)?;
    let records = std::mem::take(&mut world.resource_mut::<RunOutput>().records);
    let references = world.resource::<References>();
    let (rendered, cached) = (references.rendered, references.cached);
    let report = write_report(&folder)?;
    Ok(RunSummary {
        folder: folder.root,
        records,
        references_rendered: rendered,
        references_cached: cached,
        report,
    })
}

/// The summary, JOD maps and report.html of a run whose frames are all written, then the
/// removal of its `report.pending`.
pub(crate) fn write_report(folder: &RunFolder) -> Result<PathBuf> {
    let report = report::rebuild(&folder.root, &crate::methods::registry::charts())
        .with_context(|| format!("writing the report of {}", folder.root.display()))?;
    let pending = folder.report_pending();
    std::fs::remove_file(&pending).with_context(|| format!("removing {}", pending.display()))?;
    Ok(report)
}

/// The replayed frames' rows against those the interrupted run wrote.
fn replay_matches(world: &World, resume: &ResumeAt, folder: &RunFolder) -> Result<()> {
    let replayed = frame::frame_record::to_csv(&world.resource::<RunOutput>().records);
    crate::replayed_rows::same_rows(&folder.frames_csv(), &resume.frames_csv, &replayed)
}

fn progress_bar(enabled: bool, len: u64) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} frames  {elapsed_precise} elapsed, ETA {eta_precise}  {msg}",
        )
        .expect("valid progress template"),
    );
    bar
}
