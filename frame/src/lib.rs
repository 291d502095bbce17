//! The frame as a bevy_ecs schedule. Its stages (Simulate, Extract, Render, Learn, Measure,
//! Record) are ordered system sets; the simulation's animation systems, the upload of the
//! scene, each method's systems (added by its [`method::MethodPlugin`]; this crate knows no
//! method), the metrics and the recording are systems in them. `flicker schedule` prints what
//! runs. Also here: what the stages write (the run folder, frames.csv rows, the reference
//! cache, atomic output) and what a method is to the frame (`method`).

pub mod computation;
pub mod extract;
pub mod frame_metrics;
pub mod frame_record;
pub mod host_source;
pub mod measure;
pub mod method;
pub mod method_output;
pub mod output;
pub mod record;
pub mod reference;
pub mod reference_cache;
pub mod resources;
pub mod run_folder;
pub mod scene_medium;
pub mod stage;
pub mod temporal_window;
pub mod tonemap;

use bevy_ecs::prelude::*;

pub use method::{MethodPlugin, MethodSpec, Registered, RegisteredMethod};
pub use method_output::{MethodImage, MethodOutput};
pub use reference::References;
pub use resources::{
    FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Progress, Run, RunOutput,
};
pub use sim::ExtractedScene;
pub use stage::{
    GpuFaults, Stage, catch_failures, describe, failed, last_owner, listing, method_failed,
    new_schedule, own_systems, system_keys, take_failure,
};

fn started(clock: Res<FrameClock>) -> bool {
    clock.started
}

fn recorded(clock: Res<FrameClock>) -> bool {
    clock.recorded
}

/// The systems every frame has, whatever its methods.
pub fn add_core_systems(schedule: &mut Schedule) {
    schedule.add_systems(
        (sim::advance_clock, sim::animation_systems())
            .chain()
            .run_if(started)
            .in_set(Stage::Simulate),
    );
    schedule.add_systems(
        (
            sim::extract_scene.run_if(started),
            extract::frame_number,
            extract::upload_scene,
            scene_medium::upload_medium,
        )
            .chain()
            .in_set(Stage::Extract),
    );
    schedule.add_systems(reference::render_reference.in_set(Stage::Render));
    schedule.add_systems(
        (
            measure::prepare,
            measure::smape_vs_previous,
            measure::flip_vs_reference,
            measure::regions,
        )
            .chain()
            .run_if(recorded)
            .in_set(Stage::Measure),
    );
    schedule.add_systems(
        (
            (record::write_reference, record::write_method_images, record::write_frames_csv)
                .chain()
                .run_if(recorded),
            record::end_frame,
        )
            .chain()
            .in_set(Stage::Record),
    );
}
