//! Rendering methods. Each is a plugin ([`MethodPlugin`]): it adds its systems to the frame's
//! stages (`crate::frame::Stage`) and builds each instance, GPU state included, up front on the
//! instance's entity. Its scenario settings are its own serde struct, wrapped by
//! [`MethodSpec`]. Adding a method: its passes (render/ or its own crate), one file here with
//! its settings, components, systems and plugin, and one variant + registry line in `spec.rs`.

pub mod hash_cache;
pub mod nirc;
pub mod path_tracing;
pub mod sample_cache;
pub mod spec;
pub mod sss;
pub mod taa;
pub mod temporal_window;
pub mod termination;
pub mod volume;
pub mod volume_path;

use anyhow::Result;
use bevy_ecs::prelude::*;

pub use spec::{check_labels, parse_methods};

use hash_cache::HashCacheSettings;
use nirc::NircSettings;
use path_tracing::PathTracingSettings;
use sample_cache::SampleCacheSettings;
use serde::{Deserialize, Serialize};
use sim::MethodEntry;
use sss::SssMethodSettings;
use taa::TaaSettings;
use termination::TerminationSettings;
use volume::VolumeSettings;
use volume_path::VolumePathMethod;

/// A method family: its systems and how to build one instance.
pub trait MethodPlugin: Sync {
    /// The scenario's name of the method, e.g. `SampleCache`.
    fn name(&self) -> &'static str;
    /// Adds the method's systems to the frame's stages (once per run, whatever the number of
    /// instances; each system serves every instance).
    fn add_systems(&self, schedule: &mut Schedule);
    /// Builds one instance on `entity` (which already has its `MethodInfo` and `MethodFrame`):
    /// its GPU state, from the world's `GpuDevice` and `Tracer`.
    fn spawn(&self, world: &mut World, entity: Entity, method: &Method) -> Result<()>;
    /// Whether the method renders the scenario's participating media (issue 13); the others
    /// would render a scene with media as if it had none, so such scenarios refuse them.
    fn sees_media(&self) -> bool {
        false
    }
}

pub use crate::frame::{MethodImage, MethodOutput};

/// A rendering method and its settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum MethodSpec {
    /// NEE + MIS path tracing at `spp` samples per pixel.
    PathTracing(PathTracingSettings),
    /// Path tracing terminated into the neural incident radiance cache (nirc/README.md).
    Nirc(NircSettings),
    /// Stable sample cache (render::sample_cache).
    SampleCache(SampleCacheSettings),
    /// TAA over jittered 1 spp path tracing (render::taa).
    Taa(TaaSettings),
    /// World-space hash cache (render::hash_cache), optionally under TAA.
    HashCache(HashCacheSettings),
    /// Primary-ray transmittance images of a medium with one estimator (media crate).
    VolumeTransmittance(VolumeSettings),
    /// Volumetric path tracing of the scenario's medium (media::gpu::VolumePathPass), with MIS
    /// of equiangular and free-flight sampling by the paper's weights.
    VolumePath(VolumePathMethod),
    /// Path tracing terminated into a hashed radiance cache by variance trading
    /// (render::termination): `Termination(rule: VarianceBounding(t: 0.1))`.
    Termination(TerminationSettings),
    /// Screen-space subsurface scattering of the path tracer's image (render::sss):
    /// `Sss(variant: OnlineCv)`.
    Sss(SssMethodSettings),
}

impl MethodSpec {
    /// The method's plugin: the registry of methods, one line each.
    pub fn plugin(&self) -> &'static dyn MethodPlugin {
        match self {
            MethodSpec::PathTracing(_) => &path_tracing::PLUGIN,
            MethodSpec::Nirc(_) => &nirc::PLUGIN,
            MethodSpec::SampleCache(_) => &sample_cache::PLUGIN,
            MethodSpec::Taa(_) => &taa::PLUGIN,
            MethodSpec::HashCache(_) => &hash_cache::PLUGIN,
            MethodSpec::VolumeTransmittance(_) => &volume::PLUGIN,
            MethodSpec::VolumePath(_) => &volume_path::PLUGIN,
            MethodSpec::Termination(_) => &termination::PLUGIN,
            MethodSpec::Sss(_) => &sss::PLUGIN,
        }
    }

    /// The label of an unnamed method, e.g. `pt_4spp`.
    pub fn default_label(&self) -> String {
        match self {
            MethodSpec::PathTracing(s) => s.label(),
            MethodSpec::Nirc(s) => s.label(),
            MethodSpec::SampleCache(s) => s.label(),
            MethodSpec::Taa(_) => "taa".into(),
            MethodSpec::HashCache(s) => hash_cache::label(s),
            MethodSpec::VolumeTransmittance(s) => s.label(),
            MethodSpec::VolumePath(s) => s.label(),
            MethodSpec::Termination(s) => termination::label(s),
            MethodSpec::Sss(s) => s.label(),
        }
    }

    /// Samples (shaded paths) per pixel the method spends per frame: fractional for the sample
    /// cache's adaptive shading (its budget is shading_rate x pixels).
    pub fn spp(&self) -> f64 {
        match self {
            MethodSpec::PathTracing(s) => s.spp as f64,
            MethodSpec::Nirc(s) => s.spp as f64,
            // Uniform shading: one path per pixel (validate refuses another rate); adaptive:
            // the budget's rate.
            MethodSpec::SampleCache(s) => s.shading_rate as f64,
            MethodSpec::Taa(_) | MethodSpec::HashCache(_) | MethodSpec::Termination(_) => 1.0,
            MethodSpec::VolumeTransmittance(s) => s.spp as f64,
            MethodSpec::VolumePath(s) => s.spp as f64,
            MethodSpec::Sss(s) => s.spp as f64,
        }
    }

    /// The method's effective temporal window in frames ([`temporal_window`]: the box-filter
    /// length of equal noise variance, nominal); `None` where it is not stated: NIRC and the
    /// termination cache learn over time with no fixed blend.
    pub fn temporal_window(&self) -> Option<f64> {
        let taa = |window: f64, under: bool| {
            if under {
                temporal_window::in_series(
                    window,
                    temporal_window::exponential(TaaSettings::default().alpha as f64),
                )
            } else {
                window
            }
        };
        match self {
            MethodSpec::PathTracing(_)
            | MethodSpec::VolumeTransmittance(_)
            | MethodSpec::VolumePath(_)
            | MethodSpec::Sss(_) => Some(1.0),
            MethodSpec::Taa(s) => Some(temporal_window::exponential(s.alpha as f64)),
            MethodSpec::HashCache(s) => {
                Some(taa(temporal_window::exponential(1.0 / s.max_samples as f64), s.taa))
            }
            MethodSpec::SampleCache(s) => {
                let alpha = if s.roughness_alpha { 0.1 } else { s.alpha as f64 };
                let shades = s.n_target as f64 * temporal_window::exponential(alpha);
                Some(taa(shades / s.shading_rate as f64, s.taa))
            }
            MethodSpec::Nirc(_) | MethodSpec::Termination(_) => None,
        }
    }

    /// `--spp N`: methods whose cost is a sample count take it; the others are 1 spp by
    /// construction.
    pub fn set_spp(&mut self, spp: u32) {
        match self {
            MethodSpec::PathTracing(s) => s.spp = spp,
            MethodSpec::Nirc(s) => s.spp = spp,
            MethodSpec::VolumeTransmittance(s) => s.spp = spp,
            MethodSpec::VolumePath(s) => s.spp = spp,
            MethodSpec::Sss(s) => s.spp = spp,
            MethodSpec::SampleCache(_)
            | MethodSpec::Taa(_)
            | MethodSpec::HashCache(_)
            | MethodSpec::Termination(_) => {}
        }
    }
}

/// One method of a run: its settings, its label and where the scenario wrote it.
#[derive(Clone, Debug, PartialEq)]
pub struct Method {
    pub spec: MethodSpec,
    /// `name: "..."` of the entry, if any.
    pub name: Option<String>,
    pub entry: MethodEntry,
}

impl Method {
    /// Folder and table name: the entry's `name`, else the method's default label.
    pub fn label(&self) -> String {
        self.name.clone().unwrap_or_else(|| self.spec.default_label())
    }

    /// A method from RON text alone (tests, tools).
    pub fn parse(text: &str) -> Result<Method, String> {
        spec::parse_one(text)
    }
}

/// The plugins of `methods`, each once, in order of first use.
pub fn plugins(methods: &[Method]) -> Vec<&'static dyn MethodPlugin> {
    let mut out: Vec<&'static dyn MethodPlugin> = Vec::new();
    for m in methods {
        let p = m.spec.plugin();
        if !out.iter().any(|q| q.name() == p.name()) {
            out.push(p);
        }
    }
    out
}

/// The frame's schedule for `methods`: the core systems and each used method's systems.
pub fn schedule_for(methods: &[Method]) -> Schedule {
    let mut schedule = crate::frame::new_schedule();
    crate::frame::add_core_systems(&mut schedule);
    for plugin in plugins(methods) {
        plugin.add_systems(&mut schedule);
    }
    schedule
}

/// What `flicker schedule` prints: the methods, then the frame's systems by stage in execution
/// order. Fails if a system is in no stage or out of stage order.
pub fn describe_schedule(methods: &[Method]) -> Result<String> {
    let mut schedule = schedule_for(methods);
    let listing =
        crate::frame::listing(&mut schedule, &mut World::new()).map_err(|e| anyhow::anyhow!(e))?;
    let mut text = String::from("methods\n");
    for m in methods {
        text += &format!("  {} ({})\n", m.label(), m.spec.plugin().name());
    }
    text += &crate::frame::describe(&listing);
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The manifest's samples per pixel are the paths the method shades: adaptive shading at a
    /// 70% budget spends 0.7, uniform shading one.
    #[test]
    fn sample_cache_spp_is_its_shading_rate() {
        let adaptive = Method::parse("SampleCache(shading: Adaptive, shading_rate: 0.7)").unwrap();
        assert!((adaptive.spec.spp() - 0.7).abs() < 1e-6, "{}", adaptive.spec.spp());
        assert_eq!(Method::parse("SampleCache()").unwrap().spec.spp(), 1.0);
    }
}
