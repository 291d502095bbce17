//! Benchmarks, probes and experiments, kept out of the libraries they measure: `flicker bench`
//! (`speed`: traversal, reference paths against Mitsuba 3 (`mitsuba`, also the renderer the
//! Mitsuba tests compare against), frame time; `image_metrics`; the
//! neural cache's `nirc_throughput` and whole `nirc_frames`), the traversal measurement
//! (`traversal`) with its experiments (`ray_order`, the BVH2 traversal `bvh2*`), and the
//! wavefront path tracer (`wavefront`). No rendering method uses any of it.

pub mod bvh2;
pub mod bvh2_batch;
pub mod bvh2_geometry;
pub mod command;
pub mod image_metrics;
pub mod memory_table;
pub mod mitsuba;
pub mod nirc_frames;
pub mod nirc_targets;
pub mod nirc_throughput;
pub mod ray_order;
pub mod speed;
pub mod traversal;
pub mod wavefront;

pub use bvh2::{BVH2_STACK_SIZE, Bvh2Blas, SceneBvh2};
pub use bvh2_batch::Bvh2Traversal;
pub use bvh2_geometry::{Bvh2Geometry, SgBvh2Node};
pub use traversal::{PAIRED_ROUNDS, TraversalBench, median, traversal_benchmark};
