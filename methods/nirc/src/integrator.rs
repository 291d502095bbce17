//! Cache-terminated path tracing (NIRC): the passes of methods/nirc/shaders/cache_paths.wgsl, which
//! run on the scene on the GPU (`SceneGpu`) with their own frame parameters (`FrameBindings`).
//!
//! Per frame: `encode_paths` traces `spp` camera paths per pixel up to the termination vertex
//! and writes one `CacheQuery` per path (plus its weight and the radiance gathered before it),
//! then picks `train_records` seeded queries and extends each into a Monte Carlo target
//! (`TrainingRecord`s, compacted, in `records()`); the cache answers the queries
//! (`NeuralCache::encode_infer`) and `encode_resolve` turns the answers into the image. Nothing
//! is read back but what the caller asks for. The estimator is written out in the shader.

use crate::error::NircError;
use crate::records::{CacheAnswer, CacheQuery, TrainingRecord};
use render::compute::BufferBinding;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::{LibraryPipeline, PassLibrary};
use render::readback::read_pod;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::TimedFrame;
use serde::{Deserialize, Serialize};

/// How camera paths end in the cache and how many train it.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CachePathSettings {
    /// Vertex k at which every camera path is terminated into the cache (1 = the primary hit,
    /// NIRC's choice: the cache then carries all indirect light and the area lights' and sky's
    /// direct light, and its temporal behaviour is seen undiluted in the image). Larger k traces
    /// k - 1 bounces with full NEE + MIS first. Paths that end earlier (escape, absorption,
    /// Russian roulette) never query.
    pub termination_vertex: u32,
    /// Training records per step, picked among the frame's queries (seeded).
    pub train_records: u32,
    /// Training steps per frame, each on its own `train_records` picks and targets (public NRC:
    /// 4 steps of 16384 records).
    pub train_steps: u32,
}

impl Default for CachePathSettings {
    fn default() -> Self {
        // 2048 records: about 1.5 s of training per frame on lavapipe at width 64
        // (docs/lab/nirc-speed.md).
        Self { termination_vertex: 1, train_records: 2048, train_steps: 1 }
    }
}

render::gpu_struct! {
    /// The cache-paths passes' parameters.
    pub struct CacheParams {
        /// Pixels x spp.
        pub query_count: u32 => "u32",
        /// Training records per step.
        pub record_count: u32 => "u32",
        /// k >= 1.
        pub termination_vertex: u32 => "u32",
        pub spp: u32 => "u32",
    }
}

/// Bytes of one `QueryMeta` (weight, prefix, origin) in the shader.
const META_BYTES: u64 = 48;
/// This pass's own @group(2): params, then queries, meta, records, answers, image, motion, ray
/// counters.
const OWN_GROUP: [BufferBinding; 8] = [
    BufferBinding::read("params", "CacheParams"),
    BufferBinding::read_write("queries", "array<CacheQuery>"),
    BufferBinding::read_write("query_meta", "array<QueryMeta>"),
    // [0, record_count): the compacted training records handed to the cache;
    // [record_count, 2 record_count): one candidate per record slot, before compaction.
    BufferBinding::read_write("records", "array<TrainingRecord>"),
    BufferBinding::read_write("answers", "array<vec4f>"),
    BufferBinding::read_write("image", "array<vec4f>"),
    // Per pixel: motion of the pixel-centre primary hit (as the path tracer's G-buffer), for
    // SMAPE with reprojection.
    BufferBinding::read_write("motion", "array<vec2f>"),
    // Rays traced this frame (sg_rays_traced of every invocation): [0] camera paths (queries
    // pass, motion rays included), [1] training targets. Cleared with the queries.
    BufferBinding::read_write("ray_counters", "array<atomic<u32>>"),
];
const WORKGROUP_2D: u32 = 8;
const WORKGROUP_1D: u32 = 64;

/// Where a method's answers go and where its image comes out: one per predictor mode.
pub struct CacheOutput {
    pub answers: wgpu::Buffer,
    /// `pixels` radiance texels, then `pixels` texels of (mean σ, 0, 0, answered samples).
    pub image: wgpu::Buffer,
}

pub struct CachePaths {
    pub settings: CachePathSettings,
    width: u32,
    height: u32,
    spp: u32,
    /// The camera paths' frame parameters and scene group.
    frame: FrameBindings,
    layout: wgpu::BindGroupLayout,
    queries_pipeline: LibraryPipeline,
    targets_pipeline: LibraryPipeline,
    compact_pipeline: LibraryPipeline,
    oracle_pipeline: LibraryPipeline,
    resolve_pipeline: LibraryPipeline,
    params: wgpu::Buffer,
    queries: wgpu::Buffer,
    meta: wgpu::Buffer,
    records: wgpu::Buffer,
    /// Per pixel motion vector of the last `encode_queries`.
    motion: wgpu::Buffer,
    /// Rays traced since the last `encode_queries`: camera paths, training targets.
    ray_counters: wgpu::Buffer,
    /// Bound where a pass does not use the caller's output.
    scratch: CacheOutput,
}

impl CachePaths {
    /// The pass's program: the pass library, its structs and @group(2), cache_paths.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let types = Module::generated(
                "package::nirc::cache_path_types",
                &[CacheParams::WGSL, &crate::records::wgsl()],
            );
            let meta = render::wgsl_file!("query_meta.wgsl");
            let bindings = render::compute::group_module(
                "package::nirc::cache_path_bindings",
                2,
                &OWN_GROUP,
                &[&types, &meta],
            );
            PassLibrary::program([types, meta, bindings], [render::wgsl_file!("cache_paths.wgsl")])
        })
    }

    /// Every WGSL source of the pass (part of warm-start keys).
    pub fn shader_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| Self::program().fingerprint())
    }

    /// Passes for `scene`'s resolution at `spp` paths per pixel.
    pub fn new(
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        settings: CachePathSettings,
    ) -> Result<Self, NircError> {
        if spp == 0 {
            return Err(NircError::Config("spp must be at least 1".into()));
        }
        if settings.termination_vertex == 0 {
            return Err(NircError::Config(
                "termination_vertex must be at least 1 (1 = the primary hit)".into(),
            ));
        }
        if settings.train_records == 0 || settings.train_steps == 0 {
            return Err(NircError::Config(format!(
                "train_records ({}) and train_steps ({}) must be at least 1",
                settings.train_records, settings.train_steps
            )));
        }
        let s = scene.settings();
        let (width, height) = (s.width, s.height);
        let query_count = width as u64 * height as u64 * spp as u64;
        if query_count > u32::MAX as u64 / 2 {
            return Err(NircError::Config(format!(
                "{width}x{height} at {spp} spp is {query_count} queries, too many"
            )));
        }
        let groups = settings
            .train_records
            .div_ceil(WORKGROUP_1D)
            .max(query_count.div_ceil(WORKGROUP_1D as u64) as u32);
        if groups > gpu.limits.max_compute_workgroups_per_dimension {
            return Err(NircError::Config(format!(
                "{groups} workgroups in one dispatch, over this adapter's limit"
            )));
        }
        // No var<workgroup> in cache_paths.wgsl.
        gpu.check_workgroup_memory("nirc cache_paths", 0)?;

        let (
            layout,
            [
                queries_pipeline,
                targets_pipeline,
                compact_pipeline,
                oracle_pipeline,
                resolve_pipeline,
            ],
        ) = scene.library_pass(
            gpu,
            "cache_paths.wgsl",
            Self::program(),
            &OWN_GROUP,
            ["queries_main", "targets_main", "compact_main", "oracle_main", "resolve_main"],
        )?;
        let buffer = |label: &str, bytes: u64| crate::gpu::setup::storage(gpu, label, bytes);
        let params = CacheParams {
            query_count: query_count as u32,
            record_count: settings.train_records,
            termination_vertex: settings.termination_vertex,
            spp,
        };
        let params = gpu.buffer_init(
            "nirc cache params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::STORAGE,
        );
        let queries = buffer("nirc cache queries", query_count * size_of::<CacheQuery>() as u64)?;
        let meta = buffer("nirc query weights", query_count * META_BYTES)?;
        let records = buffer(
            "nirc training records",
            2 * settings.train_records as u64 * size_of::<TrainingRecord>() as u64,
        )?;
        let motion = buffer("nirc motion", width as u64 * height as u64 * 8)?;
        let ray_counters = buffer("nirc ray counters", 8)?;
        let mut me = Self {
            settings,
            width,
            height,
            spp,
            frame: FrameBindings::new(gpu, scene),
            layout,
            queries_pipeline,
            targets_pipeline,
            compact_pipeline,
            oracle_pipeline,
            resolve_pipeline,
            params,
            queries,
            meta,
            records,
            motion,
            ray_counters,
            scratch: CacheOutput {
                answers: buffer("nirc scratch", 16)?,
                image: buffer("nirc scratch", 16)?,
            },
        };
        me.scratch = me.output(gpu)?;
        Ok(me)
    }

    /// Answer and image buffers sized for this pass.
    pub fn output(&self, gpu: &Gpu) -> Result<CacheOutput, NircError> {
        let answers = self.query_count() as u64 * size_of::<CacheAnswer>() as u64;
        let image = 2 * self.pixels() as u64 * 16;
        gpu.check_buffer_size("nirc answers", answers)?;
        gpu.check_buffer_size("nirc image", image)?;
        let make = |label: &str, size: u64| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        Ok(CacheOutput { answers: make("nirc answers", answers), image: make("nirc image", image) })
    }

    pub fn pixels(&self) -> u32 {
        self.width * self.height
    }

    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// Queries per frame: pixels x spp, query `pixel * spp + s`.
    pub fn query_count(&self) -> u32 {
        self.pixels() * self.spp
    }

    /// `CacheQuery[query_count]` of the last `encode_paths`.
    pub fn queries(&self) -> &wgpu::Buffer {
        &self.queries
    }

    /// `TrainingRecord[train_records]` of the last `encode_paths` (compacted).
    pub fn records(&self) -> &wgpu::Buffer {
        &self.records
    }

    pub fn record_count(&self) -> u32 {
        self.settings.train_records
    }

    /// Writes the frame parameters of this pass's camera paths (`spp`, seed, frame) on the scene as
    /// last uploaded. Written at the next submission: submit before preparing another frame.
    pub fn prepare(&self, gpu: &Gpu, scene: &SceneGpu, seed: u64, frame: u32) {
        self.frame.prepare(gpu, scene, self.spp, 0, seed, frame);
    }

    /// @group(0) (this pass's frame parameters and the scene's tables), the geometry's @group(1) and
    /// this pass's @group(2) over `out`.
    fn bind_groups(&self, gpu: &Gpu, scene: &SceneGpu, out: &CacheOutput) -> [wgpu::BindGroup; 3] {
        let buffers = [
            &self.params,
            &self.queries,
            &self.meta,
            &self.records,
            &out.answers,
            &out.image,
            &self.motion,
            &self.ray_counters,
        ];
        [
            self.frame.bind_group(gpu, scene),
            scene.geometry().bind_group().clone(),
            render::compute::buffer_group(gpu, "nirc cache paths", &self.layout, &buffers),
        ]
    }

    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        groups: &[wgpu::BindGroup; 3],
        pipeline: &LibraryPipeline,
        label: &str,
        workgroups: (u32, u32),
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        });
        record(&mut pass, groups, &[(pipeline, workgroups)]);
    }

    /// One timed pass (pass `index` of `timed`) of `pipelines`, in order, each over its workgroups.
    fn timed_pass(
        &self,
        timed: &mut TimedFrame,
        index: usize,
        groups: &[wgpu::BindGroup; 3],
        pipelines: &[(&LibraryPipeline, (u32, u32))],
    ) -> Result<(), NircError> {
        timed.pass(index, |pass| record(pass, groups, pipelines))?;
        Ok(())
    }

    /// [`Self::encode_queries`] as pass `index` of a timed frame.
    pub fn queries_timed(
        &self,
        gpu: &Gpu,
        timed: &mut TimedFrame,
        index: usize,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) -> Result<(), NircError> {
        self.prepare(gpu, scene, seed, frame);
        timed.encoder().clear_buffer(&self.ray_counters, 0, None);
        let groups = self.bind_groups(gpu, scene, &self.scratch);
        self.timed_pass(timed, index, &groups, &[(&self.queries_pipeline, self.image_groups())])
    }

    /// [`Self::encode_records`] (targets, then compaction) as pass `index` of a timed frame.
    pub fn records_timed(
        &self,
        gpu: &Gpu,
        timed: &mut TimedFrame,
        index: usize,
        scene: &SceneGpu,
    ) -> Result<(), NircError> {
        let groups = self.bind_groups(gpu, scene, &self.scratch);
        let targets = (self.settings.train_records.div_ceil(WORKGROUP_1D), 1);
        self.timed_pass(
            timed,
            index,
            &groups,
            &[(&self.targets_pipeline, targets), (&self.compact_pipeline, (1, 1))],
        )
    }

    /// [`Self::encode_resolve`] as pass `index` of a timed frame.
    pub fn resolve_timed(
        &self,
        gpu: &Gpu,
        timed: &mut TimedFrame,
        index: usize,
        scene: &SceneGpu,
        out: &CacheOutput,
    ) -> Result<(), NircError> {
        let groups = self.bind_groups(gpu, scene, out);
        self.timed_pass(timed, index, &groups, &[(&self.resolve_pipeline, self.image_groups())])
    }

    fn image_groups(&self) -> (u32, u32) {
        (self.width.div_ceil(WORKGROUP_2D), self.height.div_ceil(WORKGROUP_2D))
    }

    /// Writes the frame parameters (seed, frame) and records the camera paths into `encoder`.
    /// They are written at the next submission: submit before preparing another frame.
    pub fn encode_queries(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) {
        self.prepare(gpu, scene, seed, frame);
        encoder.clear_buffer(&self.ray_counters, 0, None);
        let groups = self.bind_groups(gpu, scene, &self.scratch);
        self.pass(encoder, &groups, &self.queries_pipeline, "nirc queries", self.image_groups());
    }

    /// Records the training targets of the queries of `encode_queries` (same frame parameters).
    pub fn encode_records(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, scene: &SceneGpu) {
        let groups = self.bind_groups(gpu, scene, &self.scratch);
        self.pass(
            encoder,
            &groups,
            &self.targets_pipeline,
            "nirc training targets",
            (self.settings.train_records.div_ceil(WORKGROUP_1D), 1),
        );
        self.pass(encoder, &groups, &self.compact_pipeline, "nirc record compaction", (1, 1));
    }

    /// Test oracle: answers every query with its own Monte Carlo target of Lc.
    pub fn encode_oracle(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        out: &CacheOutput,
    ) {
        let groups = self.bind_groups(gpu, scene, out);
        self.pass(
            encoder,
            &groups,
            &self.oracle_pipeline,
            "nirc oracle",
            (self.query_count().div_ceil(WORKGROUP_1D), 1),
        );
    }

    /// Records the image from `out.answers` into `out.image`.
    pub fn encode_resolve(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        out: &CacheOutput,
    ) {
        let groups = self.bind_groups(gpu, scene, out);
        self.pass(encoder, &groups, &self.resolve_pipeline, "nirc resolve", self.image_groups());
    }

    /// Reads `out.image` back: the radiance (alpha 1) and per pixel (mean σ, answered samples).
    pub fn read_image(
        &self,
        gpu: &Gpu,
        out: &CacheOutput,
    ) -> Result<(Vec<[f32; 4]>, Vec<[f32; 4]>), NircError> {
        let texels: Vec<[f32; 4]> = read_pod(gpu, &out.image, "nirc image")?;
        let n = self.pixels() as usize;
        Ok((texels[..n].to_vec(), texels[n..2 * n].to_vec()))
    }

    /// Per pixel motion (previous image position - current, pixels) of the last
    /// `encode_queries`, from the pixel-centre primary hit as the path tracer's G-buffer.
    pub fn read_motion(&self, gpu: &Gpu) -> Result<Vec<[f32; 2]>, NircError> {
        let mut motion: Vec<[f32; 2]> = read_pod(gpu, &self.motion, "nirc motion")?;
        motion.truncate(self.pixels() as usize);
        Ok(motion)
    }

    /// Rays traced since the last `encode_queries` (camera paths, training targets), counted on
    /// the GPU as every other method's.
    pub fn read_rays(&self, gpu: &Gpu) -> Result<[u64; 2], NircError> {
        let c: Vec<u32> = read_pod(gpu, &self.ray_counters, "nirc ray counters")?;
        Ok([c[0] as u64, c[1] as u64])
    }

    /// Reads `out.answers` back (e.g. after `NeuralCache::encode_reliability`).
    pub fn read_answers(&self, gpu: &Gpu, out: &CacheOutput) -> Result<Vec<[f32; 4]>, NircError> {
        let mut answers: Vec<[f32; 4]> = read_pod(gpu, &out.answers, "nirc answers")?;
        answers.truncate(self.query_count() as usize);
        Ok(answers)
    }

    /// Per query of the last `encode_queries`: whether the path reached its termination vertex.
    pub fn read_query_valid(&self, gpu: &Gpu) -> Result<Vec<bool>, NircError> {
        let floats: Vec<[f32; 4]> = read_pod(gpu, &self.meta, "nirc query weights")?;
        Ok(floats
            .chunks_exact(3)
            .take(self.query_count() as usize)
            .map(|m| m[0][3] > 0.0)
            .collect())
    }

    /// The training records of the last frame (tests, diagnostics).
    pub fn read_records(&self, gpu: &Gpu) -> Result<Vec<TrainingRecord>, NircError> {
        let mut records: Vec<TrainingRecord> =
            read_pod(gpu, &self.records, "nirc training records")?;
        records.truncate(self.record_count() as usize);
        Ok(records)
    }
}

/// Binds `groups` (the scene with the frame parameters, the geometry, the pass's own), then
/// dispatches each of `pipelines` over its workgroups.
fn record(
    pass: &mut wgpu::ComputePass,
    groups: &[wgpu::BindGroup; 3],
    pipelines: &[(&LibraryPipeline, (u32, u32))],
) {
    for (index, group) in groups.iter().enumerate() {
        pass.set_bind_group(index as u32, group, &[]);
    }
    for (pipeline, groups) in pipelines {
        pass.set_pipeline(&pipeline.get());
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
}
