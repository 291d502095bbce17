//! Participating media for flicker: the paper "Jackknife Transmittance and MIS Weight
//! Estimation" (../shared/seeds/jackknife-transmittance.txt) and the estimators it compares.
//!
//! CPU reference (this crate's modules, f32 like the WGSL, the same PCG stream): densities
//! (`density`), super-voxels (`supervoxel`), grid traversal (`dda`), the segment of a ray in a
//! medium (`medium`), exact optical depth (`regular_tracking`), track-length, ratio tracking,
//! ray marching (Alg. 1 and 2: `optical_depth`), naive and Kettunen's biased exp(−X)
//! (`ray_marching`), unbiased ray marching, the jackknife (Eq. 4; Eq. 3 and Eq. 6 for any m in
//! `jackknife_function`), their selection (`transmittance`),
//! MIS weights (`mis`), equiangular sampling (`equiangular`) and the 1-D stratified sampling of
//! Sec. 4.1 (`stratified`). The closed-form settings of Sec. 3 and Eqs. 9/10, which only the
//! tests use, live with them (media/tests/probes/).

pub mod dda;
pub mod density;
pub mod equiangular;
pub mod gpu;
pub mod image;
pub mod jackknife;
pub mod jackknife_function;
pub mod jackknife_table;
pub mod majorant_tracking;
pub mod medium;
pub mod mesh_inside;
pub mod mis;
pub mod optical_depth;
pub mod ratio_tracking;
pub mod ray_marching;
pub mod regular_tracking;
pub mod rng;
pub mod stratified;
pub mod supervoxel;
pub mod table1_alg1;
pub mod track_length;
pub mod transmittance;
pub mod unbiased_ray_marching;

pub use density::{DensityGrid, DensityKind};
pub use medium::{Estimate, Medium, Segment};
pub use mesh_inside::MeshInside;
pub use rng::Pcg;
pub use transmittance::Estimator;
