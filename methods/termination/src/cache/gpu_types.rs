//! The structs and bindings the passes share with termination.wgsl.

use crate::settings::BYTES_PER_RECORD;
use render::compute::BufferBinding;

pub(super) const OWN_GROUP: [BufferBinding; 10] = [
    // The hash cache's parameters: its voxel keys (capacity, probe limit, LOD, jitter).
    BufferBinding::read("hc", "HashCacheParams"),
    BufferBinding::read("tc", "TcParams"),
    BufferBinding::read_write("slots", "array<atomic<u32>>"),
    BufferBinding::read_write("records", "array<TcRecord>"),
    BufferBinding::read_write("vertices", "array<TcVertex>"),
    BufferBinding::read_write("counters", "array<atomic<u32>>"),
    BufferBinding::read_write("primary_out", "array<TaaPrimary>"),
    BufferBinding::read_write("colour_out", "array<vec4f>"),
    // Surface vertices of each pixel's path (the vertex after a blend counts α).
    BufferBinding::read_write("path_length", "array<f32>"),
    // Insertion requests: indirect workgroups, count, then (candidate, home, checksum, state).
    BufferBinding::read_write("inserts", "array<atomic<u32>>"),
];

render::gpu_struct! {
    /// The method's parameters (`tc`).
    pub struct TcParams {
        pub rule_kind: u32 => "u32",
        pub relative: u32 => "u32",
        pub param: f32 => "f32",
        pub margin: f32 => "f32",
        pub bias_clamp: f32 => "f32",
        pub survival: f32 => "f32",
        pub samples_per_vertex: u32 => "u32",
        pub max_vertices: f32 => "f32",
        pub store_probability: f32 => "f32",
        /// Pixels: propagation candidates follow the pixels' in the candidate list.
        pub pixels: u32 => "u32",
        /// XOR of the candidate indices this frame: the lowest permuted index wins a record.
        pub candidate_mask: u32 => "u32",
        /// A propagation sample whose hit has no filled record: 0 its estimate is left out of
        /// filled records (`Incomplete::LeaveOut`), 1 it goes on by path tracing (`PathTrace`),
        /// 2 the estimate counts with the empty record read as 0 (`Include`).
        pub incomplete: u32 => "u32",
        /// 1: the tracer offers its primary vertices to the records (one tracer per cache); 0:
        /// it draws the same random numbers but writes nothing (a second rule on a shared
        /// cache, whose offers would repeat the first's).
        pub offers: u32 => "u32",
    }
}

render::gpu_struct! {
    /// A record's moments (luminance for the second and marginal moments), or one stored
    /// vertex's estimates of this frame (`vertices` = 1 valid, 0 none).
    #[derive(Default, PartialEq)]
    pub struct TcRecord {
        /// E[Y] (rgb): the cache value.
        pub mean: [f32; 3] => "vec3f",
        pub vertices: f32 => "f32",
        /// E[Y²].
        pub second: f32 => "f32",
        /// E[E[Y|y]²] (U-statistic over pairs).
        pub marginal: f32 => "f32",
        /// E[(f cos / p)² B²] at the segment's hit.
        pub deferred_bias2: f32 => "f32",
        /// E[B²]: the second moment of the segment's part after next-event estimation (the
        /// BSDF sample's hit), the part Russian roulette keeps with probability q.
        pub continuation2: f32 => "f32",
        /// Mean over vertices of the squared luminance of the vertex mean (a vertex estimate:
        /// its own squared luminance).
        pub mean_sq: f32 => "f32",
        /// Σ wᵢ² of the running mean's weights (moments.rs): with `mean_sq`, Var(mean).
        pub weight2: f32 => "f32",
        /// A vertex estimate: 1 if every sample's hit had a filled record (else it may only
        /// start an empty record).
        pub complete: f32 => "f32",
        pub pad: f32 => "f32",
    }
}

render::gpu_struct! {
    /// A stored vertex: the ray that hits it (propagation re-traces it for the surface).
    #[derive(Default, PartialEq)]
    pub struct TcVertex {
        pub origin: [f32; 3] => "vec3f",
        pub pad0: f32 => "f32",
        pub dir: [f32; 3] => "vec3f",
        pub pad1: f32 => "f32",
    }
}

const _: () = assert!(
    size_of::<TcParams>() == 52 && size_of::<TcRecord>() == 48 && size_of::<TcVertex>() == 32
);
const _: () = assert!(BYTES_PER_RECORD == 16 + 48 + 4 * 48 + 4 * 32 + 4 * 32 + 4 * 16);
