//! A raw density grid file baked at its own resolution is its values times sigma_t, voxel for
//! voxel (scenarios/assets/smoke_ring.density); at another resolution, nearest neighbour.

use std::path::Path;

use glam::{UVec3, Vec3};
use media::{DensityGrid, DensityKind};

#[test]
fn the_shipped_grid_bakes_to_its_values() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/assets/smoke_ring.density");
    let raw = scene::RawGrid::load(&file).unwrap();
    let kind = DensityKind::Grid { file };
    let g = DensityGrid::bake(&kind, UVec3::splat(16), 3.0, Vec3::splat(-1.0), Vec3::splat(1.0));
    assert_eq!(g.data, raw.data.iter().map(|v| 3.0 * v).collect::<Vec<_>>());
    assert!(g.max() > 2.9, "the ring reaches its peak");
    // Twice the resolution: each voxel takes the value of the file voxel holding its centre.
    let fine = DensityGrid::bake(&kind, UVec3::splat(32), 3.0, Vec3::splat(-1.0), Vec3::splat(1.0));
    assert_eq!(fine.at(UVec3::new(9, 17, 30)), g.at(UVec3::new(4, 8, 15)));
}
