//! The frame's stages as ordered system sets, and what ran: every system of the frame belongs to
//! exactly one stage, and the stages run in order (../shared/DESIGN.md, "One frame").

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};

use bevy_ecs::error::{BevyError, ErrorContext, FallbackErrorHandler};
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{ScheduleLabel, SingleThreadedExecutor, SystemKey};

use crate::resources::{FrameClock, Run};

/// The stages of one frame, in execution order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// Animation systems: rotations, flashes, boids, keyframes, scripted events.
    Simulate,
    /// World -> scene description -> GPU (only what changed).
    Extract,
    /// Each method's passes that make its image; the reference where one is wanted.
    Render,
    /// Training, weight averages, reliability statistics, cache upkeep after the image.
    Learn,
    /// SMAPE against the previous frame, FLIP against the reference.
    Measure,
    /// Images, frames.csv, progress.
    Record,
}

impl Stage {
    pub const ALL: [Stage; 6] = [
        Stage::Simulate,
        Stage::Extract,
        Stage::Render,
        Stage::Learn,
        Stage::Measure,
        Stage::Record,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::Simulate => "Simulate",
            Stage::Extract => "Extract",
            Stage::Render => "Render",
            Stage::Learn => "Learn",
            Stage::Measure => "Measure",
            Stage::Record => "Record",
        }
    }
}

/// The label of the frame's schedule.
#[derive(ScheduleLabel, Clone, Debug, PartialEq, Eq, Hash)]
pub struct Frame;

/// An empty frame: the stages chained in order, stopped after a failed system. Single threaded:
/// the systems share one GPU queue, and their order makes runs deterministic.
pub fn new_schedule() -> Schedule {
    let mut schedule = Schedule::new(Frame);
    schedule.set_executor(SingleThreadedExecutor::default());
    schedule.configure_sets(
        (
            Stage::Simulate,
            Stage::Extract,
            Stage::Render,
            Stage::Learn,
            Stage::Measure,
            Stage::Record,
        )
            .chain(),
    );
    // Each stage checks on its own, so a failure (or a GPU fault of the stages before it)
    // stops the stages after it: a frame with a fault is neither measured nor recorded.
    for stage in Stage::ALL {
        schedule.configure_sets(stage.run_if(no_failure));
    }
    schedule
}

thread_local! {
    /// The first failure of the frame being run on this thread (the executor is single threaded,
    /// so systems and the error handler run on the caller's thread).
    static FAILURE: RefCell<Option<String>> = const { RefCell::new(None) };
    /// Whose system's conditions were checked last in this frame (see [`own_systems`]): a GPU
    /// fault found before the next system is theirs.
    static LAST_OWNER: RefCell<Option<String>> = const { RefCell::new(None) };
}

fn record_failure(error: BevyError, context: ErrorContext) {
    FAILURE.with(|f| {
        let mut f = f.borrow_mut();
        if f.is_none() {
            *f = Some(format!("{}: {error}", context.name()));
        }
    });
}

fn no_failure(
    faults: Option<Res<GpuFaults>>,
    run: Option<Res<Run>>,
    clock: Option<Res<FrameClock>>,
) -> bool {
    if let Some(fault) = faults.and_then(|f| f.0.take()) {
        let frame = clock.map_or(String::from("frame"), |c| match c.recorded {
            true => format!("frame {}", c.frame),
            false => format!("warm-up frame {}", c.global),
        });
        let size = run.map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
        let owner = last_owner().map_or(String::new(), |o| format!(", {o}"));
        // A fault explains a system's error that followed it (a lost device fails every call
        // after it): the fault comes first.
        FAILURE.with(|f| {
            let mut f = f.borrow_mut();
            let then = f.take().map_or(String::new(), |e| format!(" (then: {e})"));
            *f = Some(format!("{frame}{size}{owner}: {fault}{then}"));
        });
    }
    FAILURE.with(|f| f.borrow().is_none())
}

/// Who ran the last system of this frame whose conditions were checked ([`own_systems`]):
/// "method LABEL" or "system NAME".
pub fn last_owner() -> Option<String> {
    LAST_OWNER.with(|o| o.borrow().clone())
}

/// The systems of `schedule` (added so far).
pub fn system_keys(schedule: &Schedule) -> HashSet<SystemKey> {
    schedule.graph().systems.iter().map(|(key, _, _)| key).collect()
}

/// Makes each system of `schedule` not in `before` check for a GPU fault before it runs (the
/// fault is then the previous system's owner's, and this system and the rest of the frame do
/// not run), then record `owner` as the last to run. `None`: each system is its own owner
/// ("system NAME"). A fault names the method whose pass caused it, not only the stage.
pub fn own_systems(schedule: &mut Schedule, before: &HashSet<SystemKey>, owner: Option<&str>) {
    let systems = &mut schedule.graph_mut().systems;
    let added: Vec<(SystemKey, String)> = systems
        .iter()
        .filter(|(key, _, _)| !before.contains(key))
        .map(|(key, system, _)| {
            let name = system.name().to_string();
            let short = name.rsplit("::").next().unwrap_or(&name).to_string();
            (key, owner.map_or(format!("system {short}"), str::to_string))
        })
        .collect();
    for (key, owner) in added {
        let check = move |faults: Option<Res<GpuFaults>>,
                          run: Option<Res<Run>>,
                          clock: Option<Res<FrameClock>>| {
            let ok = no_failure(faults, run, clock);
            LAST_OWNER.with(|o| *o.borrow_mut() = Some(owner.clone()));
            ok
        };
        let condition: bevy_ecs::schedule::BoxedCondition =
            Box::new(IntoSystem::into_system(check));
        if let Some(conditions) = systems.get_conditions_mut(key) {
            conditions.push(bevy_ecs::schedule::ConditionWithAccess::new(condition));
        }
    }
}

/// The device's faults (out of memory, validation) during a frame: the next stage does not run,
/// and the frame fails with the fault (render::gpu_fault).
#[derive(Resource)]
pub struct GpuFaults(pub render::gpu_fault::FaultSink);

/// Makes failed systems stop the frame (later stages are skipped) instead of panicking; the
/// error is then [`take_failure`]'s.
pub fn catch_failures(world: &mut World) {
    world.insert_resource(FallbackErrorHandler(record_failure));
    let _ = take_failure();
}

/// The failure of the last frame run on this thread, if any (and clears it).
pub fn take_failure() -> Option<String> {
    LAST_OWNER.with(|o| o.borrow_mut().take());
    FAILURE.with(|f| f.borrow_mut().take())
}

/// A system's error: the whole anyhow chain in one message.
pub fn failed(e: anyhow::Error) -> BevyError {
    BevyError::from(format!("{e:#}"))
}

/// A method system's error: the method's label, the frame, then `e`.
pub fn method_failed(label: &str, frame: u32, e: impl std::fmt::Display) -> BevyError {
    BevyError::from(format!("{label} frame {frame}: {e}"))
}

/// The frame's systems in execution order with their stage. An error names a system that is in
/// no stage, or one that would run before a system of an earlier stage.
pub fn listing(schedule: &mut Schedule, world: &mut World) -> Result<Vec<(Stage, String)>, String> {
    schedule.initialize(world).map_err(|e| format!("the frame's schedule does not build: {e}"))?;
    let mut stage_of = HashMap::new();
    for stage in Stage::ALL {
        if let Ok(keys) = schedule.graph().systems_in_set(stage.intern()) {
            for key in keys {
                stage_of.insert(*key, stage);
            }
        }
    }
    let systems = schedule.systems().map_err(|e| format!("{e}"))?;
    let mut out: Vec<(Stage, String)> = Vec::new();
    for (key, system) in systems {
        let name = short_name(&system.name().to_string());
        let Some(&stage) = stage_of.get(&key) else {
            return Err(format!("system {name} is in no stage of the frame"));
        };
        if let Some((last, last_name)) = out.last()
            && *last > stage
        {
            return Err(format!(
                "system {name} ({}) runs after {last_name} ({})",
                stage.name(),
                last.name()
            ));
        }
        out.push((stage, name));
    }
    Ok(out)
}

/// `sim::animation::rotate::rotate` -> `rotate::rotate`: the module and the function; a
/// method's systems, in its crate's `plugin` module, by the crate (`taa::plugin::resolve` ->
/// `taa::resolve`).
fn short_name(full: &str) -> String {
    let parts: Vec<&str> = full.split("::").collect();
    match parts.len() {
        0 | 1 => full.to_string(),
        n if parts[n - 2] == "plugin" => format!("{}::{}", parts[0], parts[n - 1]),
        n => format!("{}::{}", parts[n - 2], parts[n - 1]),
    }
}

/// The listing as text, grouped by stage: what `flicker schedule` prints.
pub fn describe(listing: &[(Stage, String)]) -> String {
    let mut text = String::new();
    for stage in Stage::ALL {
        text += &format!("{}\n", stage.name());
        for (_, name) in listing.iter().filter(|(s, _)| *s == stage) {
            text += &format!("  {name}\n");
        }
    }
    text
}
