//! Plain-Rust reference of the cache: the ground truth the GPU tests compare against.

pub mod cache;
pub mod encoding;
pub mod loss;
pub mod mlp;
pub mod optimizer;
pub mod real;
