//! A run's memory: the device bytes of the scene on the GPU and of each method's state (the
//! difference of wgpu's allocator totals around their building, `render::memory`), the device
//! bytes after the last frame, and the process's peak resident memory. Written to manifest.json
//! (`memory`) and from there to the report's summary; `flicker bench` prints a table of it
//! (bench's `memory_table`).

use bevy_ecs::prelude::*;
use serde::Serialize;

use frame::GpuDevice;

/// One method instance's device memory.
#[derive(Clone, Debug, Serialize)]
pub struct MethodMemory {
    pub label: String,
    /// Bytes of the buffers and textures its building allocated; `None` where the backend has
    /// no allocator report.
    pub device_bytes: Option<i64>,
    /// Those buffers and textures by label, largest first (empty where there is no report).
    pub buffers: Vec<(String, u64)>,
}

/// The run's memory (a resource of the frame's world; `playback` fills it).
#[derive(Resource, Clone, Debug, Default, Serialize)]
pub struct RunMemory {
    /// The scene on the GPU: scene bindings, geometry, the path tracer's outputs, the media.
    pub scene_device_bytes: Option<i64>,
    /// In the scenario's order.
    pub methods: Vec<MethodMemory>,
    /// Everything the run had allocated when its world was built (the sum of the above).
    pub device_bytes_built: Option<u64>,
    /// Everything allocated after the last frame: above `device_bytes_built` where something
    /// was allocated during the frames and kept.
    pub device_bytes_end: Option<u64>,
    /// Device memory the allocator had reserved in blocks after the last frame (wgpu's own
    /// allocations and free space included).
    pub device_reserved_bytes_end: Option<u64>,
    /// The process's peak resident memory (VmHWM) after the last frame, before the report.
    pub peak_resident_bytes: Option<u64>,
    /// The process's resident memory (VmRSS) after the last frame: what the run holds at its
    /// end, where the peak is usually set while pipelines compile at its start.
    pub resident_bytes_end: Option<u64>,
    /// The process's memory after 1, 2, 4, 8, ... frames played (warm-up included) and after
    /// the last: growth over one run, read within one process (two processes of the same
    /// scenario end tens of MiB apart, so growth is not read across runs).
    pub by_frame: Vec<MemorySample>,
}

/// The process's memory after some frames.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MemorySample {
    /// Frames played so far, warm-up included.
    pub frames: u32,
    /// Resident memory (VmRSS): what the machine lends the process, freed pages included.
    pub resident_bytes: Option<u64>,
    /// What the allocator has handed out and not taken back (`render::memory::heap_bytes`):
    /// memory the run holds, where a leak shows at once.
    pub heap_bytes: Option<u64>,
}

impl MemorySample {
    fn now(frames: u32) -> Self {
        Self {
            frames,
            resident_bytes: render::memory::resident_bytes(),
            heap_bytes: render::memory::heap_bytes(),
        }
    }
}

impl RunMemory {
    /// After each frame: samples the memory at powers of two of the frames played (a reading
    /// walks the allocator's arenas; twenty of them cover a million frames).
    pub fn frame_played(world: &mut World, frames: u32) {
        if frames.is_power_of_two() {
            world.resource_mut::<RunMemory>().by_frame.push(MemorySample::now(frames));
        }
    }

    /// Records the end of the frames: device bytes, the peak resident memory, and the last
    /// sample of `by_frame`.
    pub fn finish(world: &mut World, frames: u32) {
        let gpu = &world.resource::<GpuDevice>().0;
        let end = render::memory::device_bytes(gpu);
        let reserved = render::memory::device_reserved_bytes(gpu);
        let mut memory = world.resource_mut::<RunMemory>();
        memory.device_bytes_end = end;
        memory.device_reserved_bytes_end = reserved;
        memory.peak_resident_bytes = render::memory::peak_resident_bytes();
        let last = MemorySample::now(frames);
        memory.resident_bytes_end = last.resident_bytes;
        if memory.by_frame.last().is_none_or(|s| s.frames != frames) {
            memory.by_frame.push(last);
        }
    }
}
