//! GPU faults end a run as errors that name the pass and the size, never as wgpu's panic:
//! - a device whose limits are below what the scene needs (limits read from the adapter, the
//!   device granted a quarter of the scene's per-pixel bytes): the run fails while it is built,
//!   before its folder is touched;
//! - during a frame, a buffer over the adapter's buffer limit at a resolution well inside its
//!   texture limit, a validation error of a compute pass and a lost device: the error names the
//!   method whose pass faulted, the frame is neither measured nor recorded, manifest.json says
//!   `failed` with the error and the last complete frame, and the frames before it stay whole;
//! - a method's setting that sizes a buffer over the adapter's limit: the run fails while it is
//!   built, naming the method, its buffer and the bytes.
//!
//! The frame faults come from a method defined here (`FaultyPass`), registered like any other.

use std::path::{Path, PathBuf};

use anyhow::Result;
use bevy_ecs::prelude::*;
use frame::{FrameClock, GpuDevice, MethodFrame, Run, Stage};
use playback::methods::{MethodOutput, MethodPlugin, register};
use playback::play::{RunOptions, run_spec, run_spec_on};
use playback::scenario::{Overrides, RunSpec};
use serde::{Deserialize, Serialize};

const W: u32 = 16;
const H: u32 = 9;
/// The recorded frame at which the fixture faults (frames 0 and 1 are whole).
const AT: u32 = 2;

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
enum Fault {
    /// A per-pixel buffer of one byte more than the adapter's `max_buffer_size` in total.
    #[default]
    OverBufferLimit,
    /// A compute pass that dispatches without a pipeline.
    Validation,
    /// The device destroyed, as a driver reset or a removed GPU loses it.
    DeviceLost,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct FaultySettings {
    fault: Fault,
}

#[derive(Component)]
struct FaultyState(Fault);

/// `FaultyPass(fault: ...)`: a black image each frame, and the fault at frame [`AT`].
struct FaultyPlugin;

impl MethodPlugin for FaultyPlugin {
    type Settings = FaultySettings;
    const NAME: &'static str = "FaultyPass";

    fn label(settings: &FaultySettings) -> String {
        format!("faulty_{:?}", settings.fault)
    }

    fn spp(_: &FaultySettings) -> f64 {
        1.0
    }

    fn temporal_window(_: &FaultySettings) -> Option<f64> {
        Some(1.0)
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(faulty_render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &FaultySettings) -> Result<()> {
        world.entity_mut(entity).insert(FaultyState(settings.fault));
        Ok(())
    }
}

fn faulty_render(
    gpu: Res<GpuDevice>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&FaultyState, &mut MethodFrame)>,
) {
    let (gpu, pixels) = (&gpu.0, (run.width * run.height) as u64);
    for (state, mut frame) in &mut methods {
        if clock.recorded && clock.frame == AT {
            match state.0 {
                Fault::OverBufferLimit => {
                    // The adapter's limit, not the device's: a real device may grant less.
                    let per_pixel = gpu.adapter.limits().max_buffer_size / pixels + 1;
                    let _ = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("faulty per-pixel records"),
                        size: (pixels * per_pixel).next_multiple_of(4),
                        usage: wgpu::BufferUsages::STORAGE,
                        mapped_at_creation: false,
                    });
                }
                Fault::Validation => {
                    // Labelled by its pass, as `render::timing::PassTimer` labels a pass's encoder.
                    let mut encoder =
                        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                            label: Some("faulty_shade"),
                        });
                    {
                        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                            label: Some("faulty_shade"),
                            timestamp_writes: None,
                        });
                        pass.dispatch_workgroups(run.width.div_ceil(8), run.height.div_ceil(8), 1);
                    }
                    gpu.queue.submit([encoder.finish()]);
                }
                Fault::DeviceLost => {
                    // As a method's readback would: the device reports its loss when polled.
                    gpu.device.destroy();
                    let _ = gpu.device.poll(wgpu::PollType::Poll);
                }
            }
        }
        let black = vec![[0.0, 0.0, 0.0, 1.0]; pixels as usize];
        frame.output = Some(MethodOutput::timed(black, vec![[0.0; 2]; pixels as usize], &[], 0, 0));
    }
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-gpu-faults-{name}-")).tempdir().unwrap()
}

fn spec(dir: &Path, methods: &str) -> (RunSpec, RunOptions) {
    let file = dir.join("faults.ron");
    std::fs::write(
        &file,
        format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: ({W}, {H}), frames: 4,\n  reference: (spp: 1, frames: List([])),\n  methods: [{methods}])"
        ),
    )
    .unwrap();
    let overrides = Overrides { out: Some(dir.join("run")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions {
        scenario: file,
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    (spec, opts)
}

fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.push(path);
        }
    }
    out
}

#[test]
fn faults_during_a_frame_fail_the_run_naming_the_pass_and_the_size() {
    // Once per process: the registry is global.
    register::<FaultyPlugin>().unwrap();
    let gpu = render::gpu::Gpu::new().unwrap();
    let pixels = u64::from(W * H);
    let bytes = (pixels * (gpu.adapter.limits().max_buffer_size / pixels + 1)).next_multiple_of(4);
    drop(gpu);
    for (fault, pass, size) in [
        // wgpu names the buffer and its bytes; the frame adds the resolution.
        (Fault::OverBufferLimit, "faulty per-pixel records", bytes.to_string()),
        (Fault::Validation, "faulty_shade", format!("{W}x{H}")),
        (Fault::DeviceLost, "GPU device lost", format!("{W}x{H}")),
    ] {
        let tmp = scratch(&format!("{fault:?}"));
        let dir = tmp.path().to_path_buf();
        let (spec, opts) =
            spec(&dir, &format!("FaultyPass(fault: {fault:?}), PathTracing(spp: 1)"));
        let err = format!("{:#}", run_spec(&spec, &opts).err().expect("the fault fails the run"));
        eprintln!("{fault:?}: {err}");
        let resolution = format!("{W}x{H}");
        // The method whose pass faulted, though PathTracing's systems run after it.
        let method = format!("method faulty_{fault:?}");
        for part in [pass, &size, &resolution, &format!("frame {AT}"), &method] {
            assert!(err.contains(part), "{fault:?}: the error names '{part}': {err}");
        }
        let run = dir.join("run");
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(run.join("manifest.json")).unwrap())
                .unwrap();
        assert_eq!(manifest["status"], "failed", "{manifest}");
        assert_eq!(manifest["last_complete_frame"], AT - 1, "{manifest}");
        let recorded = manifest["error"].as_str().unwrap_or_default();
        assert!(recorded.contains(pass) && recorded.contains(&resolution), "{recorded}");
        // Nothing of the faulty frame: no rows, no images, no temporary files.
        let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
        let frames: Vec<&str> = csv.lines().skip(1).filter_map(|l| l.split(',').nth(1)).collect();
        assert_eq!(frames, ["0", "0", "1", "1"], "{csv}");
        let files = files_under(&run);
        let stray: Vec<_> = files
            .iter()
            .filter(|p| {
                let name = p.file_name().unwrap().to_string_lossy();
                name.contains(".tmp") || name.starts_with(&format!("{AT:04}"))
            })
            .collect();
        assert!(stray.is_empty(), "{fault:?}: {stray:?}");
    }
}

#[test]
fn a_device_below_the_scenes_needs_fails_before_anything_is_written() {
    let tmp = scratch("limits");
    let dir = tmp.path().to_path_buf();
    let (spec, opts) = spec(&dir, "PathTracing(spp: 1)");
    // A quarter of the bytes of one RGBA f32 image at the run's resolution: the path tracer's
    // per-pixel buffers, and the scene's, need more.
    let granted = u64::from(W * H) * 16 / 4;
    let mut gpu = render::gpu::Gpu::with_device_limits(|adapter| wgpu::Limits {
        max_buffer_size: granted.min(adapter.max_buffer_size),
        max_storage_buffer_binding_size: granted.min(adapter.max_storage_buffer_binding_size),
        ..adapter.clone()
    })
    .expect("a device with lower limits");
    // The checks before the GPU read these: the adapter's, as a driver that advertises more
    // than it can hold.
    gpu.limits = gpu.adapter.limits();
    let err =
        format!("{:#}", run_spec_on(&spec, &opts, gpu).err().expect("the device is too small"));
    eprintln!("{err}");
    for part in ["faults.ron", "GPU validation error", "Buffer size", &format!("{W}x{H}")] {
        assert!(err.contains(part), "the error names '{part}': {err}");
    }
    assert!(
        err.contains("uploading the scene") || err.contains("preparing method"),
        "the error names the step: {err}"
    );
    assert!(!dir.join("run").exists(), "a run that fails while built writes nothing");
}

#[test]
fn a_setting_that_sizes_a_buffer_over_the_limit_names_the_method_and_the_bytes() {
    let tmp = scratch("setting");
    let dir = tmp.path().to_path_buf();
    // A device granted at most 1 GiB per buffer (the adapter's limit where smaller), so that a
    // table one slot over it stays inside the setting's range on any adapter.
    let cap = |l: u64| l.min(1 << 30);
    let gpu = render::gpu::Gpu::with_device_limits(|adapter| wgpu::Limits {
        max_buffer_size: cap(adapter.max_buffer_size),
        max_storage_buffer_binding_size: cap(adapter.max_storage_buffer_binding_size),
        ..adapter.clone()
    })
    .expect("a device with a 1 GiB buffer limit");
    let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    // 16 bytes per slot: one slot more than the limit holds.
    let capacity = limit / 16 + 1;
    let (spec, opts) = spec(&dir, &format!("PathTracing(spp: 1), HashCache(capacity: {capacity})"));
    let err =
        format!("{:#}", run_spec_on(&spec, &opts, gpu).err().expect("the table is too large"));
    eprintln!("{err}");
    let bytes = (capacity * 16).to_string();
    for part in ["faults.ron:3:", "preparing method hash_cache", "hash cache slots", &bytes] {
        assert!(err.contains(part), "the error names '{part}': {err}");
    }
    assert!(!dir.join("run").exists(), "a run that fails while built writes nothing");
}
