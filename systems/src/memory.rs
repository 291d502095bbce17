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
}

impl RunMemory {
    /// Records the end of the frames: device bytes and the peak resident memory.
    pub fn finish(world: &mut World) {
        let gpu = &world.resource::<GpuDevice>().0;
        let end = render::memory::device_bytes(gpu);
        let reserved = render::memory::device_reserved_bytes(gpu);
        let mut memory = world.resource_mut::<RunMemory>();
        memory.device_bytes_end = end;
        memory.device_reserved_bytes_end = reserved;
        memory.peak_resident_bytes = render::memory::peak_resident_bytes();
        memory.resident_bytes_end = render::memory::resident_bytes();
    }
}
