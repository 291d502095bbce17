//! Rendering methods. Each is a plugin ([`MethodPlugin`], in `plugin.rs`): it owns its settings,
//! label, samples per pixel, temporal window and `--spp` override, adds its systems to the
//! frame's stages (`frame::Stage`) and builds each instance, GPU state included, up front
//! on the instance's entity, and declares the statistics and charts it records. `registry.rs`
//! lists them, one line each. Adding a method: its folder under `methods/` with its settings,
//! components, systems and plugin, and its registry line.

pub mod registry;
pub mod spec;

use anyhow::Result;
use bevy_ecs::prelude::*;

pub use frame::method::{
    Better, ChartSeries, Computed, DeclaredComputation, FolderInput, FolderRun, FolderSeries,
    FolderStatistic, MethodChart, MethodPlugin, MethodSpec, RegisteredMethod, Source, Statistic,
};
pub use frame::temporal_window;
pub use registry::register;
pub use spec::{check_labels, parse_methods};

use sim::MethodEntry;

pub use frame::{MethodImage, MethodOutput};

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
pub fn plugins(methods: &[Method]) -> Vec<&'static dyn RegisteredMethod> {
    let mut out: Vec<&'static dyn RegisteredMethod> = Vec::new();
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
    let mut schedule = frame::new_schedule();
    frame::add_core_systems(&mut schedule);
    // Each system is owned by its method (or is the frame's own), so a GPU fault names it.
    frame::own_systems(&mut schedule, &Default::default(), None);
    for plugin in plugins(methods) {
        let before = frame::system_keys(&schedule);
        plugin.add_systems(&mut schedule);
        let labels: Vec<String> = methods
            .iter()
            .filter(|m| m.spec.plugin().name() == plugin.name())
            .map(Method::label)
            .collect();
        let owner = format!("method {}", labels.join(", "));
        frame::own_systems(&mut schedule, &before, Some(&owner));
    }
    schedule
}

/// What `flicker schedule` prints: the methods, then the frame's systems by stage in execution
/// order. Fails if a system is in no stage or out of stage order.
pub fn describe_schedule(methods: &[Method]) -> Result<String> {
    let mut schedule = schedule_for(methods);
    let listing =
        frame::listing(&mut schedule, &mut World::new()).map_err(|e| anyhow::anyhow!(e))?;
    let mut text = String::from("methods\n");
    for m in methods {
        text += &format!("  {} ({})\n", m.label(), m.spec.plugin().name());
    }
    text += &frame::describe(&listing);
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
