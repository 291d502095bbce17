//! The path-traced reference of a frame where the scenario asks for one: from the reference
//! cache, else rendered (and cached).

use bevy_ecs::prelude::*;

use super::resources::{FrameClock, GpuDevice, GpuScene, Progress, Run};
use super::stage::failed;
use crate::frame_metrics as measure;
use crate::reference_cache::{Lookup, ReferenceCache, ReferenceKey};
use media::gpu::SubsurfacePathPass;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::path_tracer::PathTracer;
use render::scene_gpu::SceneGpu;

/// The reference of this frame, where the scenario wants one, the reference cache and what
/// renders the references.
#[derive(Resource)]
pub struct References {
    pub cache: ReferenceCache,
    /// None when the scenario wants no reference.
    pub renderer: Option<ReferenceRenderer>,
    /// Linear radiance of this frame's reference and the same ready to measure.
    pub current: Option<(Vec<[f32; 4]>, measure::Frame)>,
    pub rendered: u32,
    pub cached: u32,
}

/// What renders the references, with its own frame parameters and outputs.
pub enum ReferenceRenderer {
    /// A scenario without media: the path tracer.
    Path(Box<PathTracer>),
    /// A scenario with media: the volumetric path tracer (the pass is `SceneMedium`'s, shared
    /// with the VolumePath methods), with the references' frame parameters.
    Volume(FrameBindings),
    /// `reference: (random_walk: true)`: subsurface materials as media inside their meshes
    /// (media::gpu::SubsurfacePathPass), with the references' frame parameters.
    RandomWalk(Box<SubsurfacePathPass>, FrameBindings),
}

impl ReferenceRenderer {
    pub fn new(gpu: &Gpu, scene: &SceneGpu, media: bool) -> anyhow::Result<Self> {
        Ok(if media {
            Self::Volume(FrameBindings::new(gpu, scene))
        } else {
            Self::Path(Box::new(PathTracer::new(gpu, scene)?))
        })
    }

    /// The random-walk reference of subsurface materials (a scenario without media).
    pub fn random_walk(gpu: &Gpu, scene: &SceneGpu) -> anyhow::Result<Self> {
        let pass = SubsurfacePathPass::new(gpu, scene).map_err(anyhow::Error::msg)?;
        Ok(Self::RandomWalk(Box::new(pass), FrameBindings::new(gpu, scene)))
    }
}

/// References use their own random sequence, so they never share noise with a method.
pub fn reference_seed(seed: u64) -> u64 {
    seed ^ 0x05ee_d0f4_efe4_e9ce
}

/// Render stage: this frame's reference into [`References::current`] (or `None`).
pub fn render_reference(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    progress: Res<Progress>,
    mut references: ResMut<References>,
    mut medium: Option<ResMut<super::scene_medium::SceneMedium>>,
) -> Result {
    references.current = None;
    let scenario = &run.scenario;
    if !clock.recorded || !scenario.reference.wants(clock.frame, scenario.frames) {
        return Ok(());
    }
    let (width, height) = (run.width, run.height);
    let settings = gpu_scene.0.settings();
    // With a medium the volumetric path tracer renders the reference: its shaders, the medium
    // and its state are part of the key.
    let shader_source = match &medium {
        Some(m) => format!(
            "{}\n{}\n{}",
            PathTracer::shader_source(),
            media::gpu::VolumePathPass::shader_source(),
            m.cache_key()
        ),
        None if scenario.reference.random_walk => {
            format!("random walk\n{}", SubsurfacePathPass::shader_source())
        }
        None => PathTracer::shader_source().to_string(),
    };
    let key = ReferenceCache::key(
        &scene.scene,
        &ReferenceKey {
            width,
            height,
            spp: scenario.reference.spp,
            seed: reference_seed(scenario.seed),
            max_depth: scenario.max_depth,
            rr_start_depth: settings.rr_start_depth,
            adapter: &gpu.0.summary.to_string(),
            shader_source: &shader_source,
            host_source: crate::host_source::HASH,
        },
    );
    let frame = clock.frame;
    let references = &mut *references;
    let mut lookup = references.cache.lookup(&key, width, height);
    // A miss takes the entry's lock and looks again: another run or sweep job may have rendered
    // it meanwhile, and whoever holds the lock renders it while the others wait.
    let lock = match lookup {
        Lookup::Hit(_) => None,
        Lookup::Miss | Lookup::Damaged(_) => {
            let lock = references
                .cache
                .lock(&key, || {
                    progress.0.set_message(format!(
                        "reference {frame:04}: waiting for another run rendering it"
                    ))
                })
                .map_err(failed)?;
            lookup = references.cache.lookup(&key, width, height);
            Some(lock)
        }
    };
    if let Lookup::Damaged(why) = &lookup {
        progress.0.suspend(|| {
            eprintln!("warning: reference cache entry damaged, rendering it again: {why}")
        });
    }
    let pixels = match lookup {
        Lookup::Hit(px) => {
            references.cached += 1;
            px
        }
        Lookup::Miss | Lookup::Damaged(_) => {
            let bar = &progress.0;
            bar.set_message(format!("reference {frame:04}"));
            let spp = scenario.reference.spp;
            let fail = |e: &dyn std::fmt::Display| {
                failed(anyhow::anyhow!("reference of frame {frame}: {e}"))
            };
            let px = match (references.renderer.as_mut(), medium.as_deref_mut()) {
                (Some(ReferenceRenderer::Volume(bindings)), Some(m)) => {
                    super::scene_medium::render_volume(
                        &gpu.0,
                        &gpu_scene.0,
                        bindings,
                        m,
                        &super::scene_medium::REFERENCE_SETTINGS,
                        spp,
                        reference_seed(scenario.seed),
                        clock.global,
                    )
                    .map(|(px, _, _)| px)
                    .map_err(|e| fail(&e))?
                }
                (Some(ReferenceRenderer::RandomWalk(pass, bindings)), None) => pass
                    .render(
                        &gpu.0,
                        &gpu_scene.0,
                        bindings,
                        &scene.scene.materials,
                        spp,
                        reference_seed(scenario.seed),
                        clock.global,
                    )
                    .map(|image| image.mean.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect())
                    .map_err(|e| fail(&e))?,
                (Some(ReferenceRenderer::Path(tracer)), None) => tracer
                    .render_reference(
                        &gpu.0,
                        &gpu_scene.0,
                        spp,
                        reference_seed(scenario.seed),
                        clock.global,
                        &mut |done, total| {
                            bar.set_message(format!("reference {frame:04}: {done}/{total} spp"));
                        },
                    )
                    .map_err(|e| fail(&e))?,
                _ => return Err(fail(&"no reference renderer for this scenario")),
            };
            references.cache.store(&key, width, height, &px).map_err(failed)?;
            references.rendered += 1;
            px
        }
    };
    drop(lock);
    let measured = measure::Frame::from_radiance(width, height, &pixels, None);
    references.current = Some((pixels, measured));
    Ok(())
}
