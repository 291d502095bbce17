//! One rule's tracer over the cache: its buffers, bind group and building.

use super::gpu_types::TcParams;
use super::passes::TC_TRACE_PASS;
use super::statistics::COUNTERS;
use crate::settings::TerminationSettings;
use render::gpu::Gpu;
use render::timing::PassTimer;
use taa::TaaPrimary;

/// One rule's tracer over a [`TerminationCache`]: its parameters (`tc`: the rule, survival),
/// its counters and per-pixel outputs, and a bind group with the cache's shared buffers. Rules
/// whose settings have the same [`TerminationSettings::cache_key`] build the same records, so
/// one cache serves them all: its propagation, fold, insertion and store run once a frame, and
/// each rule runs only `tc_trace` ([`TerminationCache::trace_with`]).
///
/// [`TerminationCache`]: super::TerminationCache
/// [`TerminationCache::trace_with`]: super::TerminationCache::trace_with
pub struct TerminationTracer {
    pub(super) settings: TerminationSettings,
    /// Whether this tracer's primary vertices are offered to the records (the first tracer of a
    /// cache; the others' offers are the same vertices, see `TcParams::offers`).
    pub(super) offers: bool,
    pub(super) tc: wgpu::Buffer,
    /// Only the trace's words (path vertices, trace rays, unknown records) are this tracer's;
    /// the cache's passes count in the cache's own tracer.
    pub(super) counters: wgpu::Buffer,
    pub(super) primary: wgpu::Buffer,
    pub(super) colour: wgpu::Buffer,
    pub(super) path_length: wgpu::Buffer,
    pub(super) group: wgpu::BindGroup,
    pub(super) timer: PassTimer,
}

impl TerminationTracer {
    pub fn settings(&self) -> TerminationSettings {
        self.settings
    }
}

/// The cache's buffers every tracer binds.
#[derive(Clone, Copy)]
pub(super) struct SharedBuffers<'a> {
    pub(super) hc: &'a wgpu::Buffer,
    pub(super) slots: &'a wgpu::Buffer,
    pub(super) records: &'a wgpu::Buffer,
    pub(super) vertices: &'a wgpu::Buffer,
    pub(super) inserts: &'a wgpu::Buffer,
}

/// A tracer's own buffers (sizes checked by [`TerminationCache::new`]) and its bind group.
///
/// [`TerminationCache::new`]: super::TerminationCache::new
pub(super) fn build_tracer(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    shared: SharedBuffers,
    settings: TerminationSettings,
    offers: bool,
    pixels: u64,
) -> TerminationTracer {
    let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
        gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let rw =
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let tc = buffer(
        "termination tc",
        size_of::<TcParams>() as u64,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    let counters = buffer("termination counters", COUNTERS * 4, rw);
    let primary = buffer("termination primary", pixels * size_of::<TaaPrimary>() as u64, rw);
    let colour = buffer("termination colour", pixels * 16, rw);
    let path_length = buffer("termination path length", pixels * 4, rw);
    let group = render::compute::buffer_group(
        gpu,
        "termination",
        layout,
        &[
            shared.hc,
            &tc,
            shared.slots,
            shared.records,
            shared.vertices,
            &counters,
            &primary,
            &colour,
            &path_length,
            shared.inserts,
        ],
    );
    TerminationTracer {
        settings,
        offers,
        tc,
        counters,
        primary,
        colour,
        path_length,
        group,
        timer: PassTimer::new(gpu, &[TC_TRACE_PASS]),
    }
}
