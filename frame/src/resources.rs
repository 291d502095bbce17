//! What the frame's systems share: the GPU, the scene on it, the run, the frame's number and
//! the records (resources; the references' is `reference::References`), and each method
//! instance's frame (components of the method's entity).

use std::path::PathBuf;

use bevy_ecs::prelude::*;
use indicatif::ProgressBar;
use render::gpu::Gpu;
use render::scene_gpu::SceneGpu;
use sim::Scenario;

use super::method_output::MethodOutput;
use crate::frame_metrics as measure;
use crate::frame_record::FrameRecord;
use crate::run_folder::RunFolder;

/// The device every pass runs on.
#[derive(Resource)]
pub struct GpuDevice(pub Gpu);

/// The scene on the GPU (geometry and BVH, materials, textures, lights, camera, its features)
/// and the pass library every method's passes are built on; updated once per frame in Extract.
/// Every method reads it with its own frame parameters.
#[derive(Resource)]
pub struct GpuScene(pub SceneGpu);

/// The run: its scenario and where its cached state lives.
#[derive(Resource)]
pub struct Run {
    pub scenario: Scenario,
    pub width: u32,
    pub height: u32,
    /// `--cache-dir`: references, and state a method may reuse across runs (NIRC warm starts).
    pub cache_dir: PathBuf,
}

/// Which frame this schedule run is.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct FrameClock {
    /// Recorded frame (0 for the first recorded frame; warm-up frames come before it).
    pub frame: u32,
    /// Simulation frame (warm-up frames included), the seed of per-frame randomness.
    pub global: u32,
    /// False during warm-up: methods render (caches learn) but nothing is measured or written.
    pub recorded: bool,
    /// False on the very first run: the world already holds frame 0, Simulate does not step.
    pub started: bool,
}

/// The run folder and the rows of frames.csv so far.
#[derive(Resource)]
pub struct RunOutput {
    pub folder: RunFolder,
    pub records: Vec<FrameRecord>,
    /// A resumed run's recorded frames below this are on disk already: they are played again
    /// (to rebuild the methods' state) and measured, but not written.
    pub replay_until: u32,
}

/// The progress bar (hidden with `--quiet`).
#[derive(Resource)]
pub struct Progress(pub ProgressBar);

/// One method instance: its place in the scenario and its label.
#[derive(Component, Clone, Debug)]
pub struct MethodInfo {
    /// Position in the scenario's `methods` (the order of frames.csv rows).
    pub index: usize,
    pub label: String,
}

/// One method's frame as it moves through the stages: Render/Learn fill `output`, Measure
/// fills `record`, Record writes both and keeps `current` as the next frame's `previous`.
#[derive(Component, Default)]
pub struct MethodFrame {
    pub output: Option<MethodOutput>,
    /// CPU time of this frame's method systems, ms.
    pub cpu_ms: f64,
    pub current: Option<measure::Frame>,
    pub previous: Option<measure::Frame>,
    pub record: FrameRecord,
    pub smape_map: Option<Vec<f32>>,
    pub flip_map: Option<Vec<f32>>,
}

impl MethodFrame {
    /// Adds the CPU time since `start` to the frame's CPU time.
    pub fn add_cpu(&mut self, start: std::time::Instant) {
        self.cpu_ms += start.elapsed().as_secs_f64() * 1e3;
    }
}
