//! What a method is to the lab: a [`MethodPlugin`] owns everything the rest of the code asks of
//! a method (its scenario name, label, samples per pixel, temporal window, the `--spp`
//! override, its systems, how to build an instance, and the statistics and charts it records),
//! so that nothing outside its own folder matches on which method it is. [`MethodSpec`] holds one method's settings behind that trait;
//! the registry (`playback::methods::registry`) lists the plugins.

use std::any::Any;
use std::fmt;
use std::marker::PhantomData;

use anyhow::Result;
use bevy_ecs::prelude::{Entity, Schedule, World};
use serde::Serialize;
use serde::de::DeserializeOwned;

pub use crate::computation::{Computed, ComputedValues, DeclaredComputation};
pub use report::declared::{
    Better, ChartSeries, FolderInput, FolderRun, FolderSeries, FolderStatistic, MethodChart,
    Source, Statistic,
};

/// A method family, implemented once per method on a unit struct (`taa::Plugin`). Its settings
/// are a serde struct; a scenario writes `NAME(field: value, ...)`.
pub trait MethodPlugin: Sync + Send + 'static {
    /// The method's settings as a scenario writes them (every field defaulted where it can be).
    type Settings: Clone
        + fmt::Debug
        + PartialEq
        + Serialize
        + DeserializeOwned
        + Send
        + Sync
        + 'static;

    /// The scenario's name of the method, e.g. `SampleCache`.
    const NAME: &'static str;

    /// The smallest entry of its settings a scenario may write: `()` where every field has a
    /// default (the documentation test reads the settings' fields and defaults from it).
    const MINIMAL_SETTINGS: &'static str = "()";

    /// The statistics it records besides every method's numbers (its frames.csv `stats`, and
    /// what `flicker reproduce` computes for it): claims and suites name them.
    const STATISTICS: &'static [Statistic] = &[];

    /// The charts its frames.csv columns get in the report.
    const CHARTS: &'static [MethodChart] = &[];

    /// Its paper's test cases that claims compute instead of play (closed forms, CPU Monte
    /// Carlo), by the name a claims file writes.
    const COMPUTATIONS: &'static [DeclaredComputation] = &[];

    /// The label of an unnamed instance, e.g. `pt_4spp`: its folder and its rows' key.
    fn label(settings: &Self::Settings) -> String;

    /// Samples (shaded paths) per pixel the method spends per frame; fractional where it shades
    /// a share of the pixels.
    fn spp(settings: &Self::Settings) -> f64;

    /// Its effective temporal window in frames (`crate::temporal_window`); `None` where it is
    /// not stated (methods that learn over time with no fixed blend).
    fn temporal_window(settings: &Self::Settings) -> Option<f64>;

    /// `--spp N`: methods whose cost is a sample count take it; the others keep their own.
    fn set_spp(_settings: &mut Self::Settings, _spp: u32) {}

    /// Whether the method renders the scenario's participating media; the others would render
    /// a scene with media as if it had none, so such scenarios refuse them.
    fn sees_media() -> bool {
        false
    }

    /// Whether an instance with these settings writes the per-frame image map `name` (its
    /// `MethodOutput` extra images, e.g. NIRC's `preference`): a statistic read from such maps
    /// ([`FolderInput::EventAndMap`]) is refused on methods that write none.
    fn writes_image(_settings: &Self::Settings, _name: &str) -> bool {
        false
    }

    /// Adds the method's systems to the frame's stages (once per run, whatever the number of
    /// instances; each system serves every instance).
    fn add_systems(schedule: &mut Schedule);

    /// Builds one instance on `entity` (which already has its `MethodInfo` and `MethodFrame`):
    /// its GPU state, from the world's resources.
    fn spawn(world: &mut World, entity: Entity, settings: &Self::Settings) -> Result<()>;
}

/// A method family as the registry holds it: the typed plugin behind an object.
pub trait RegisteredMethod: Sync {
    fn name(&self) -> &'static str;
    /// Settings from RON text (the entry with its name blanked): `ron` is the text with the
    /// method's identifier replaced by spaces, so positions stay those of the entry.
    fn parse(
        &self,
        ron: &str,
        options: &ron::Options,
    ) -> Result<MethodSpec, ron::error::SpannedError>;
    fn add_systems(&self, schedule: &mut Schedule);
    fn sees_media(&self) -> bool;
    fn statistics(&self) -> &'static [Statistic];
    fn charts(&self) -> &'static [MethodChart];
    fn computations(&self) -> &'static [DeclaredComputation];
}

/// The registry's entry of plugin `P` (`Registered::<taa::Plugin>::ENTRY`).
pub struct Registered<P>(PhantomData<fn() -> P>);

impl<P: MethodPlugin> Registered<P> {
    pub const ENTRY: Registered<P> = Registered(PhantomData);
}

impl<P: MethodPlugin> RegisteredMethod for Registered<P> {
    fn name(&self) -> &'static str {
        P::NAME
    }

    fn parse(
        &self,
        ron: &str,
        options: &ron::Options,
    ) -> Result<MethodSpec, ron::error::SpannedError> {
        let settings: P::Settings = options.from_str(ron)?;
        Ok(MethodSpec::new::<P>(settings))
    }

    fn add_systems(&self, schedule: &mut Schedule) {
        P::add_systems(schedule)
    }

    fn sees_media(&self) -> bool {
        P::sees_media()
    }

    fn statistics(&self) -> &'static [Statistic] {
        P::STATISTICS
    }

    fn charts(&self) -> &'static [MethodChart] {
        P::CHARTS
    }

    fn computations(&self) -> &'static [DeclaredComputation] {
        P::COMPUTATIONS
    }
}

/// One method's settings, typed by its plugin and held as an object: what `methods: [...]`
/// parses to.
pub struct MethodSpec(Box<dyn AnySettings>);

impl MethodSpec {
    /// Settings of plugin `P`.
    pub fn new<P: MethodPlugin>(settings: P::Settings) -> Self {
        MethodSpec(Box::new(Typed::<P> { settings, plugin: PhantomData }))
    }

    /// The method's scenario name, e.g. `Taa`.
    pub fn name(&self) -> &'static str {
        self.0.name()
    }

    /// The method's registry entry (its systems, whether it sees media).
    pub fn plugin(&self) -> &'static dyn RegisteredMethod {
        self.0.plugin()
    }

    /// The label of an unnamed instance.
    pub fn default_label(&self) -> String {
        self.0.label()
    }

    /// Samples (shaded paths) per pixel per frame.
    pub fn spp(&self) -> f64 {
        self.0.spp()
    }

    /// The effective temporal window in frames, where stated.
    pub fn temporal_window(&self) -> Option<f64> {
        self.0.temporal_window()
    }

    /// `--spp N`, where the method takes it.
    pub fn set_spp(&mut self, spp: u32) {
        self.0.set_spp(spp)
    }

    /// Whether it writes the per-frame image map `name` (`MethodPlugin::writes_image`).
    pub fn writes_image(&self, name: &str) -> bool {
        self.0.writes_image(name)
    }

    /// Builds one instance on `entity`.
    pub fn spawn(&self, world: &mut World, entity: Entity) -> Result<()> {
        self.0.spawn(world, entity)
    }

    /// The settings if they are of type `S` (tests, tools).
    pub fn get<S: 'static>(&self) -> Option<&S> {
        self.0.settings().downcast_ref()
    }

    /// The settings, mutable, if they are of type `S`.
    pub fn get_mut<S: 'static>(&mut self) -> Option<&mut S> {
        self.0.settings_mut().downcast_mut()
    }

    /// Whether the settings are of type `S`.
    pub fn is<S: 'static>(&self) -> bool {
        self.get::<S>().is_some()
    }

    /// The settings' serde form (the fields, without the method's name).
    pub fn settings_json(&self) -> serde_json::Result<serde_json::Value> {
        self.0.to_json()
    }

    /// The same method with settings read from their serde form.
    pub fn with_settings_json(&self, value: serde_json::Value) -> serde_json::Result<MethodSpec> {
        self.0.json_to_spec(value)
    }
}

impl Clone for MethodSpec {
    fn clone(&self) -> Self {
        MethodSpec(self.0.clone_box())
    }
}

impl PartialEq for MethodSpec {
    fn eq(&self, other: &Self) -> bool {
        self.0.eq_dyn(&*other.0)
    }
}

impl fmt::Debug for MethodSpec {
    /// As the scenario writes it: `Taa(TaaSettings { .. })`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple(self.name()).field(&self.0.settings_debug()).finish()
    }
}

/// Serialised as an externally tagged enum, `{"Taa": {...}}` in JSON: the manifest's form.
impl Serialize for MethodSpec {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let value = self.settings_json().map_err(serde::ser::Error::custom)?;
        let mut map = serializer.serialize_map(Some(1))?;
        map.serialize_entry(self.name(), &value)?;
        map.end()
    }
}

/// What [`MethodSpec`] needs of its settings, object-safe.
trait AnySettings: Send + Sync {
    fn name(&self) -> &'static str;
    fn plugin(&self) -> &'static dyn RegisteredMethod;
    fn label(&self) -> String;
    fn spp(&self) -> f64;
    fn temporal_window(&self) -> Option<f64>;
    fn set_spp(&mut self, spp: u32);
    fn writes_image(&self, name: &str) -> bool;
    fn spawn(&self, world: &mut World, entity: Entity) -> Result<()>;
    fn settings(&self) -> &dyn Any;
    fn settings_mut(&mut self) -> &mut dyn Any;
    fn settings_debug(&self) -> &dyn fmt::Debug;
    fn to_json(&self) -> serde_json::Result<serde_json::Value>;
    fn json_to_spec(&self, value: serde_json::Value) -> serde_json::Result<MethodSpec>;
    fn clone_box(&self) -> Box<dyn AnySettings>;
    fn eq_dyn(&self, other: &dyn AnySettings) -> bool;
}

struct Typed<P: MethodPlugin> {
    settings: P::Settings,
    plugin: PhantomData<fn() -> P>,
}

impl<P: MethodPlugin> AnySettings for Typed<P> {
    fn name(&self) -> &'static str {
        P::NAME
    }

    fn plugin(&self) -> &'static dyn RegisteredMethod {
        // A zero-sized value: leaking its box allocates nothing.
        Box::leak(Box::new(Registered::<P>::ENTRY))
    }

    fn label(&self) -> String {
        P::label(&self.settings)
    }

    fn spp(&self) -> f64 {
        P::spp(&self.settings)
    }

    fn temporal_window(&self) -> Option<f64> {
        P::temporal_window(&self.settings)
    }

    fn set_spp(&mut self, spp: u32) {
        P::set_spp(&mut self.settings, spp)
    }

    fn writes_image(&self, name: &str) -> bool {
        P::writes_image(&self.settings, name)
    }

    fn spawn(&self, world: &mut World, entity: Entity) -> Result<()> {
        P::spawn(world, entity, &self.settings)
    }

    fn settings(&self) -> &dyn Any {
        &self.settings
    }

    fn settings_mut(&mut self) -> &mut dyn Any {
        &mut self.settings
    }

    fn settings_debug(&self) -> &dyn fmt::Debug {
        &self.settings
    }

    fn to_json(&self) -> serde_json::Result<serde_json::Value> {
        serde_json::to_value(&self.settings)
    }

    fn json_to_spec(&self, value: serde_json::Value) -> serde_json::Result<MethodSpec> {
        Ok(MethodSpec::new::<P>(serde_json::from_value(value)?))
    }

    fn clone_box(&self) -> Box<dyn AnySettings> {
        Box::new(Typed::<P> { settings: self.settings.clone(), plugin: PhantomData })
    }

    fn eq_dyn(&self, other: &dyn AnySettings) -> bool {
        other.name() == P::NAME
            && other.settings().downcast_ref::<P::Settings>() == Some(&self.settings)
    }
}
