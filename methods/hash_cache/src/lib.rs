//! World-space hash cache: the HashCache baseline of stable-sample-caching.txt (§4, §5).
//!
//! What follows the paper: voxels hashed twice (home slot + checksum), linear probing (open
//! addressing) within a bounded window, a last-access stamp per entry and eviction of entries
//! not accessed for a while, level of detail from the camera distance and optionally the
//! incidence angle (its Fig. 9), voxel jitter before lookup [BFK18], jittered first hits at 1 spp,
//! one secondary path per reserved cell per frame (the pixel that reserves a cell traces, the
//! others only look up), albedo demodulation, the cell a running mean (non-resampled temporal
//! filtering), optional TAA on the result.
//!
//! Departures, and why:
//! - `lookup`: [`HashCacheLookup::FirstHit`] (the default) is the paper's placement (cells at
//!   primary hits, albedo demodulated; with lod_scale 1 voxels are the largest power of two not
//!   above the pixel footprint, i.e. smaller than a pixel, as its §5 chooses), and the paper runs
//!   it under TAA (`taa: true`, what the reprojection scenarios run as `hash_cache_taa`).
//!   [`HashCacheLookup::SecondaryHit`] (a variant, label `hash_cache_secondary_hit`)
//!   terminates the first bounce into the cache at its hit and caches outgoing radiance there
//!   (not albedo demodulated).
//! - Keys: WGSL has no 64-bit atomics, so the paper's 64-bit (last access, checksum) word becomes
//!   a 32-bit checksum claimed by compare-exchange plus a separate last-access word every
//!   accessor stores the same frame into; the home slot is stored for checking.
//! - Which pixel reserves a cell: the lowest pixel index (atomicMin), not the first to arrive, so
//!   that the one writer of each cell, and hence the image, does not depend on scheduling. The
//!   slot a key lands in may (when home windows overlap), which changes nothing visible unless
//!   a probe window overflows (counted in `insert_failures`; those pixels use their own sample).
//! - Eviction is a per-slot pass at the start of the frame (entries older than `max_age`
//!   frames), not lazy overwrite at insertion: a lookup never races an eviction.
//! - No 2D tiling of the slots by the normal's major axis ([BMdD*23] memory coherence); the axis
//!   is part of the key instead, which keeps the two sides of thin walls apart.
//! - Four passes (age, trace, update, resolve) rather than two: the claim must be complete
//!   before the claimant is known.
//! - Cells are not split into parent/child levels (that is the paper's Hybrid, not HashCache).
//!
//! Numbers below predate the exact voxel sizes (voxels then rounded up to a power of two,
//! secondary-hit default); not rerun since. Later convergence numbers are in
//! docs/lab/sample-cache-passes.md.
//!
//! Numbers (lavapipe, 2 shared CPU cores; an earlier courtyard version of cache_methods_bench at 320x180,
//! camera moving, max depth 4, median GPU ms): secondary-hit lookup hc_age 5.2,
//! hc_trace 334, hc_update 581, hc_resolve 6.2 (occupancy 0.17 of 2^18 slots, 18k update paths
//! for 57.6k pixels); first-hit lookup 6.6 / 152 / 503 / 4.3 (occupancy 0.07); TAA trace 1034,
//! resolve 11. fast_turn.ron at 64x36: mean frame-to-frame SMAPE 1 spp 0.46, hash cache 0.39,
//! TAA 0.15, hash cache + TAA 0.13; relMSE at the reference frames 0.072, 0.052, 0.015-0.027,
//! 0.010-0.023. Hairball 320x180, max depth 3, idle machine (`cargo run -j2 -p bench --example
//! cache_methods_bench -- 320 180 12`, table in docs/lab/sample-cache-fig7.md): hc_age 7.5,
//! hc_trace 537, hc_update 399, hc_resolve 3.5 ms; 141 027 rays and 64 211 shaded paths
//! (57 600 pixels + update paths) per frame.

pub mod key;
pub mod table_cpu;

use render::compute::BufferBinding;
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::readback::{copy_all, read_pod};
use render::scene::Camera;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};
use taa::{Taa, TaaPrimary, halton_jitter};

pub use key::KeyParams;
pub use table_cpu::{CpuHashTable, CpuSlot};

pub const HC_AGE_PASS: &str = "hc_age";
pub const HC_TRACE_PASS: &str = "hc_trace";
pub const HC_UPDATE_PASS: &str = "hc_update";
pub const HC_RESOLVE_PASS: &str = "hc_resolve";
/// The cache's own @group(2) (declared into its WGSL).
const OWN_GROUP: [BufferBinding; 7] = [
    BufferBinding::read("hc", "HashCacheParams"),
    BufferBinding::read_write("slots", "array<atomic<u32>>"),
    // rgb mean, w samples.
    BufferBinding::read_write("cell_radiance", "array<vec4f>"),
    BufferBinding::read_write("records", "array<HcRecord>"),
    BufferBinding::read_write("counters", "array<atomic<u32>>"),
    BufferBinding::read_write("primary_out", "array<TaaPrimary>"),
    BufferBinding::read_write("colour_out", "array<vec4f>"),
];

/// Entry points, in the order of [`HcPass`] (its discriminant indexes the pipelines).
const PASSES: [&str; 4] = [HC_AGE_PASS, HC_TRACE_PASS, HC_UPDATE_PASS, HC_RESOLVE_PASS];

/// The cache's passes in frame order; each is timed under its name (frames.csv's column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HcPass {
    /// Per slot: eviction, claims reset.
    Age,
    /// Per pixel: primary ray, key point, find-or-insert, claim.
    Trace,
    /// Per pixel: each cell's claimant folds one path into it.
    Update,
    /// Per pixel: the colour from the updated cells (the image).
    Resolve,
}

impl HcPass {
    /// The cache's upkeep before the image, in one submission ([`HashCache::update`]).
    pub const UPDATE: [HcPass; 3] = [HcPass::Age, HcPass::Trace, HcPass::Update];

    pub fn name(self) -> &'static str {
        PASSES[self as usize]
    }
}

/// Where the path terminates into the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum HashCacheLookup {
    /// The paper (the default): cells at the primary hits, albedo demodulated, sub-pixel voxels.
    FirstHit,
    /// The first bounce ends in the cache at its hit (outgoing radiance there).
    SecondaryHit,
}

/// The `HashCache(...)` method's scenario settings; every field defaults to [`Default`]'s value.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HashCacheSettings {
    /// Slots of the table.
    pub capacity: u32,
    /// Slots probed from the home slot before an insertion fails.
    pub probe_limit: u32,
    /// Entries not accessed for more than this many frames are evicted.
    pub max_age: u32,
    /// Voxel size in pixel footprints at the point's camera distance (rounded down to 2^k: at 1,
    /// voxels smaller than a pixel).
    pub lod_scale: f32,
    /// Widen voxels at grazing incidence (the paper's distance + normal LOD).
    pub normal_lod: bool,
    /// Voxel jitter before lookup.
    pub jitter: bool,
    pub lookup: HashCacheLookup,
    /// Running mean of a cell up to this many samples, then exponential (weight 1/max_samples).
    pub max_samples: u32,
    /// Halton (2, 3) cycle of the primary rays; 0 = pixel centres.
    pub jitter_length: u32,
    /// Resolve the cache's image under TAA (default settings), as the paper runs it.
    pub taa: bool,
}

impl Default for HashCacheSettings {
    fn default() -> Self {
        Self {
            capacity: 1 << 18,
            probe_limit: 8,
            max_age: 8,
            lod_scale: 1.0,
            normal_lod: true,
            jitter: true,
            lookup: HashCacheLookup::FirstHit,
            max_samples: 32,
            jitter_length: 8,
            taa: false,
        }
    }
}

impl HashCacheSettings {
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |m: String| Err(RenderError::Settings(m));
        if self.capacity == 0 || self.capacity >= u32::MAX / 4 {
            return bad(format!(
                "hash cache capacity must be in 1..2^30 slots, got {}",
                self.capacity
            ));
        }
        if self.probe_limit == 0 || self.probe_limit > self.capacity {
            return bad(format!(
                "hash cache probe_limit must be in 1..=capacity, got {}",
                self.probe_limit
            ));
        }
        if self.max_samples == 0 || !(self.lod_scale > 0.0) {
            return bad("hash cache max_samples must be at least 1 and lod_scale positive".into());
        }
        Ok(())
    }

    /// Key parameters for a camera and image height.
    pub fn key_params(&self, camera: &Camera, height: u32) -> KeyParams {
        KeyParams {
            capacity: self.capacity,
            pixel_angle: 2.0 * (0.5 * camera.vfov).tan() / height as f32,
            lod_scale: self.lod_scale,
            normal_lod: self.normal_lod,
            jitter: self.jitter,
        }
    }
}

render::gpu_struct! {
    /// The cache's parameters (`hc`, its @group(2) binding 0).
    pub struct HashCacheParams {
        pub capacity: u32 => "u32",
        pub probe_limit: u32 => "u32",
        /// Frame + 1 (0 marks never accessed).
        pub frame: u32 => "u32",
        pub max_age: u32 => "u32",
        /// 2 tan(vfov / 2) / height: pixel footprint per unit distance.
        pub pixel_angle: f32 => "f32",
        pub lod_scale: f32 => "f32",
        pub normal_lod: u32 => "u32",
        pub jitter: u32 => "u32",
        /// 0 first hit (the paper), 1 first secondary hit.
        pub lookup: u32 => "u32",
        pub max_samples: f32 => "f32",
        pub voxel_jitter_seed: u32 => "u32",
        pub pad: u32 => "u32",
        pub primary_jitter: [f32; 2] => "vec2f",
        pub pad2: [f32; 2] => "vec2f",
    }
}

render::gpu_struct! {
    /// A pixel's state between the passes.
    #[derive(Default, PartialEq)]
    pub struct HcRecord {
        /// The key point's hit (instance, primitive, bits of the barycentrics), so that the
        /// update starts from it instead of tracing the key ray again.
        pub key_hit: [u32; 4] => "vec4u",
        pub key_point: [f32; 3] => "vec3f",
        /// HC_NONE: no key point, or insertion failed.
        pub slot: u32 => "u32",
        pub key_normal: [f32; 3] => "vec3f",
        pub checksum: u32 => "u32",
        pub direct: [f32; 3] => "vec3f",
        pub home: u32 => "u32",
        pub modulate: [f32; 3] => "vec3f",
        pub rng: u32 => "u32",
        pub ray_origin: [f32; 3] => "vec3f",
        /// Path vertex index of the key point.
        pub depth: u32 => "u32",
        pub ray_dir: [f32; 3] => "vec3f",
        /// pack2x16unorm.
        pub voxel_jitter: u32 => "u32",
        /// The pixel's own update sample when it has no cell.
        pub own_sample: [f32; 3] => "vec3f",
        /// HC_NEEDS_SAMPLE.
        pub flags: u32 => "u32",
    }
}

pub const HC_NEEDS_SAMPLE: u32 = 1;

const _: () = assert!(size_of::<HashCacheParams>() == 64 && size_of::<HcRecord>() == 128);

/// Cache counters of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HashCacheStats {
    pub capacity: u32,
    /// Entries after this frame's insertions.
    pub occupied: u32,
    pub evicted: u32,
    pub inserted: u32,
    /// Lookups whose probe window was full (those pixels used their own sample).
    pub insert_failures: u32,
    /// Secondary paths traced for updates (one per reserved cell + failures).
    pub update_paths: u32,
    /// Rays traced by hc_trace and hc_update (camera, shadow, bounce), counted on the GPU.
    pub rays: u32,
}

impl HashCacheStats {
    pub fn occupancy(&self) -> f64 {
        self.occupied as f64 / self.capacity as f64
    }
}

#[derive(Clone, Debug, Default)]
pub struct HashCacheOutput {
    /// Linear radiance (after TAA when one was given), row-major, alpha = 1.
    pub radiance: Vec<[f32; 4]>,
    pub motion: Vec<[f32; 2]>,
    pub stats: HashCacheStats,
    /// The four cache passes, then TAA's resolve when used.
    pub timings: Vec<PassTiming>,
    /// Rays traced this frame ([`HashCacheStats::rays`]).
    pub rays: u64,
    /// Paths shaded: one per pixel (its primary hit, ended into the cache) plus the update paths.
    pub shaded: u64,
}

pub struct HashCache {
    settings: HashCacheSettings,
    width: u32,
    height: u32,
    params: wgpu::Buffer,
    slots: wgpu::Buffer,
    cells: wgpu::Buffer,
    records: wgpu::Buffer,
    counters: wgpu::Buffer,
    primary: wgpu::Buffer,
    colour: wgpu::Buffer,
    frame: FrameBindings,
    group: wgpu::BindGroup,
    /// Indexed by [`HcPass`].
    pipelines: [render::pass_library::LibraryPipeline; 4],
    /// One timer per submission: [`HcPass::UPDATE`], the resolve.
    update_timer: PassTimer,
    resolve_timer: PassTimer,
    /// Frames rendered so far; the stamp of the next one is `frames + 1`.
    frames: u32,
}

impl HashCache {
    pub fn new(
        gpu: &Gpu,
        scene: &SceneGpu,
        settings: HashCacheSettings,
    ) -> Result<Self, RenderError> {
        settings.validate()?;
        let s = scene.settings();
        let (width, height) = (s.width, s.height);
        gpu.check_resolution(width, height, size_of::<HcRecord>() as u64 + 32 + 16)?;
        gpu.check_buffer_size("hash cache slots", settings.capacity as u64 * 16)?;
        gpu.check_buffer_size("hash cache cells", settings.capacity as u64 * 16)?;
        // No pass declares var<workgroup>.
        gpu.check_workgroup_memory(HC_TRACE_PASS, 0)?;
        let device = &gpu.device;
        let pixels = width as u64 * height as u64;
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let rw = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let params = buffer(
            "hash cache params",
            size_of::<HashCacheParams>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let slots = buffer("hash cache slots", settings.capacity as u64 * 16, rw);
        let cells = buffer("hash cache cells", settings.capacity as u64 * 16, rw);
        let records = buffer("hash cache records", pixels * size_of::<HcRecord>() as u64, rw);
        let counters = buffer("hash cache counters", 32, rw);
        let primary = buffer("hash cache primary", pixels * size_of::<TaaPrimary>() as u64, rw);
        let colour = buffer("hash cache colour", pixels * 16, rw);

        let own = OWN_GROUP;
        let (layout, pipelines) =
            scene.library_pass(gpu, "hash_cache.wgsl", Self::program(), &own, PASSES)?;
        let group = render::compute::buffer_group(
            gpu,
            "hash cache",
            &layout,
            &[&params, &slots, &cells, &records, &counters, &primary, &colour],
        );
        Ok(Self {
            settings,
            width,
            height,
            params,
            slots,
            cells,
            records,
            counters,
            primary,
            colour,
            frame: FrameBindings::new(gpu, scene),
            group,
            pipelines,
            update_timer: PassTimer::new(gpu, &HcPass::UPDATE.map(HcPass::name)),
            resolve_timer: PassTimer::new(gpu, &[HC_RESOLVE_PASS]),
            frames: 0,
        })
    }

    /// The passes' program: the shading library, TAA's structs and primary attributes, the
    /// cache's structs and @group(2), its keys, hash_cache.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let taa_types = taa::types_module();
            let types = types_module();
            let bindings = render::compute::group_module(
                "package::hash_cache_bindings",
                2,
                &OWN_GROUP,
                &[&taa_types, &types],
            );
            PassLibrary::program(
                [taa_types, taa::primary_module(), types, bindings, key_module()],
                [render::wgsl_file!("hash_cache.wgsl")],
            )
        })
    }

    pub fn settings(&self) -> HashCacheSettings {
        self.settings
    }

    /// Frames rendered so far.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// One frame; `camera` is the scene's camera of this frame (its field of view sets the LOD),
    /// `taa` an optional resolve over the result (the paper applies TAA to HashCache).
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
        taa: Option<&mut Taa>,
    ) -> Result<HashCacheOutput, RenderError> {
        let (timings, jitter) = self.update(gpu, scene, camera, seed, frame)?;
        self.resolve(gpu, scene, taa, timings, jitter)
    }

    /// The cache's upkeep in one timed submission: age (eviction), then the frame's lookups and
    /// updates. Returns their times and the frame's primary jitter (for [`Self::resolve`]).
    pub fn update(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
    ) -> Result<(Vec<PassTiming>, [f32; 2]), RenderError> {
        let jitter = halton_jitter(frame, self.settings.jitter_length);
        let stamp = self.frames + 1;
        let k = self.settings.key_params(camera, self.height);
        let params = HashCacheParams {
            capacity: self.settings.capacity,
            probe_limit: self.settings.probe_limit,
            frame: stamp,
            max_age: self.settings.max_age,
            pixel_angle: k.pixel_angle,
            lod_scale: k.lod_scale,
            normal_lod: k.normal_lod as u32,
            jitter: k.jitter as u32,
            lookup: (self.settings.lookup == HashCacheLookup::SecondaryHit) as u32,
            max_samples: self.settings.max_samples as f32,
            voxel_jitter_seed: (seed as u32) ^ 0x5bd1e995,
            pad: 0,
            primary_jitter: jitter,
            pad2: [0.0; 2],
        };
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        gpu.queue.write_buffer(&self.counters, 0, &[0u8; 32]);
        Ok((self.submit(gpu, scene, &self.update_timer, &HcPass::UPDATE)?, jitter))
    }

    /// The frame's image after [`Self::update`] (`timings`: its times, reported first): the
    /// cache's colour (`hc_resolve`, its own submission), or `taa`'s resolve of it after.
    pub fn resolve(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        taa: Option<&mut Taa>,
        mut timings: Vec<PassTiming>,
        jitter: [f32; 2],
    ) -> Result<HashCacheOutput, RenderError> {
        // hc_resolve reads only the cache's buffers and the frame's size from the cache's frame
        // parameters, written by `update`: no need to write them again.
        timings.extend(self.submit(gpu, scene, &self.resolve_timer, &[HcPass::Resolve])?);
        let radiance = match taa {
            Some(taa) => {
                let out = taa.resolve_external(gpu, jitter, |encoder, colour, primary| {
                    encoder.copy_buffer_to_buffer(&self.colour, 0, colour, 0, self.colour.size());
                    encoder.copy_buffer_to_buffer(
                        &self.primary,
                        0,
                        primary,
                        0,
                        self.primary.size(),
                    );
                })?;
                timings.extend(out.timings);
                out.radiance
            }
            None => read_pod(gpu, &self.colour, "hash cache colour")?,
        };
        let [counters, primary] = copy_all(
            gpu,
            [(&self.counters, "hash cache counters"), (&self.primary, "hash cache primary hits")],
        );
        let c: Vec<u32> = counters.read(gpu)?;
        let primary: Vec<TaaPrimary> = primary.read(gpu)?;
        self.frames += 1;
        let stats = HashCacheStats {
            capacity: self.settings.capacity,
            occupied: c[0] + c[2],
            evicted: c[1],
            inserted: c[2],
            insert_failures: c[3],
            update_paths: c[4],
            rays: c[5],
        };
        let shaded = self.width as u64 * self.height as u64 + stats.update_paths as u64;
        Ok(HashCacheOutput {
            radiance,
            motion: primary.iter().map(|p| p.motion).collect(),
            stats,
            timings,
            rays: stats.rays as u64,
            shaded,
        })
    }

    /// `passes` in order as one submission timed by `timer` (whose names are theirs).
    fn submit(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        timer: &PassTimer,
        passes: &[HcPass],
    ) -> Result<Vec<PassTiming>, RenderError> {
        let mut timed = timer.begin(gpu, "hash cache");
        for (index, &p) in passes.iter().enumerate() {
            debug_assert_eq!(timer.names()[index], p.name());
            let pipeline = &self.pipelines[p as usize];
            let [x, y] = match p {
                HcPass::Age => [self.settings.capacity.div_ceil(64), 1],
                HcPass::Trace | HcPass::Update | HcPass::Resolve => {
                    [self.width.div_ceil(8), self.height.div_ceil(8)]
                }
            };
            timed.pass(index, |pass| {
                pass.set_pipeline(&pipeline.get());
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, &self.group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            })?;
        }
        timed.submit()
    }

    /// The table as stored: (checksum, last access, claim, home) per slot → [`CpuSlot`]s.
    pub fn read_slots(&self, gpu: &Gpu) -> Result<Vec<CpuSlot>, RenderError> {
        let raw: Vec<[u32; 4]> = read_pod(gpu, &self.slots, "hash cache slots")?;
        Ok(raw
            .into_iter()
            .map(|s| CpuSlot { checksum: s[0], last_access: s[1], home: s[3] })
            .collect())
    }

    /// Each slot's radiance (rgb) and sample count (w).
    pub fn read_cells(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, RenderError> {
        read_pod(gpu, &self.cells, "hash cache cells")
    }

    /// The per-pixel records of the last frame.
    pub fn read_records(&self, gpu: &Gpu) -> Result<Vec<HcRecord>, RenderError> {
        read_pod(gpu, &self.records, "hash cache records")
    }
}

/// The cache's structs (`package::hash_cache_types`), also imported by the termination cache,
/// which keys its records with hash_key.wgsl.
pub fn types_module() -> Module {
    Module::generated("package::hash_cache_types", &[HashCacheParams::WGSL, HcRecord::WGSL])
}

pub mod plugin;
pub use plugin::Plugin;

/// The cache's key and hash functions (`package::hash_cache::hash_key`), which the termination
/// cache's records share.
pub fn key_module() -> render::shader::Module {
    render::wgsl_file!("hash_key.wgsl")
}
