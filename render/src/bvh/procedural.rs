//! Procedural meshes and rays: the traversal tests' and the bench's inputs, and the rays the
//! stack bound is checked with.

use glam::{Vec2, Vec3};

use super::{RayQuery, SplitMix64};
use crate::scene::Mesh;

/// `count` rays with origins uniform in the box `bounds` grown by 10% of its diagonal, uniform
/// directions (unit length) and the given `t_max`; the same seed gives the same rays.
pub fn random_rays(bounds: (Vec3, Vec3), count: usize, t_max: f32, seed: u64) -> Vec<RayQuery> {
    let mut rng = SplitMix64::new(seed);
    let margin = Vec3::splat(0.1 * (bounds.1 - bounds.0).length().max(1e-3));
    let (lo, hi) = (bounds.0 - margin, bounds.1 + margin);
    (0..count)
        .map(|_| {
            let origin =
                Vec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z));
            RayQuery { origin, direction: rng.unit_vector(), t_max }
        })
        .collect()
}

/// A unit sphere with a seeded bumpy displacement (a few random sinusoids along the normal),
/// tessellated as a latitude-longitude grid with at least `min_triangles` triangles. Has smooth
/// normals and uvs. `displaced_sphere(100_000, seed)` is the benchmark's 100k-triangle mesh.
pub fn displaced_sphere(min_triangles: u32, seed: u64) -> Mesh {
    // 2 triangles per grid cell except one per cell in the two polar rows; slices = 2 * stacks.
    let mut stacks = 2u32;
    while 2 * (2 * stacks) * stacks - 2 * (2 * stacks) < min_triangles {
        stacks += 1;
    }
    let slices = 2 * stacks;
    let mut rng = SplitMix64::new(seed);
    let waves: Vec<(Vec3, f32, f32)> = (0..6)
        .map(|_| (rng.unit_vector(), rng.range(3.0, 12.0), rng.range(0.0, std::f32::consts::TAU)))
        .collect();
    let radius = |d: Vec3| {
        1.0 + waves.iter().map(|&(k, f, phase)| 0.02 * (f * k.dot(d) + phase).sin()).sum::<f32>()
    };

    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for i in 0..=stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(d * radius(d));
            uvs.push(Vec2::new(j as f32 / slices as f32, i as f32 / stacks as f32));
        }
    }
    let at = |i: u32, j: u32| i * (slices + 1) + j;
    let mut indices = Vec::new();
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Counter-clockwise seen from outside; in the polar rows one triangle of the cell
            // would be degenerate (a = d at the north pole, b = c at the south pole).
            if i != stacks - 1 {
                indices.push([a, c, b]);
            }
            if i != 0 {
                indices.push([a, d, c]);
            }
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &indices {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    for n in &mut normals {
        *n = n.normalize_or(Vec3::Y);
    }
    Mesh {
        name: format!("displaced sphere ({} triangles)", indices.len()),
        positions,
        normals,
        uvs,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displaced_sphere_has_the_triangles_asked_and_faces_outwards() {
        let m = displaced_sphere(100_000, 3);
        assert!(m.indices.len() >= 100_000 && m.indices.len() < 105_000, "{}", m.indices.len());
        let mut outward = 0;
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            if (b - a).cross(c - a).dot(a + b + c) > 0.0 {
                outward += 1;
            }
        }
        assert!(
            outward as f64 > 0.999 * m.indices.len() as f64,
            "{outward} of {}",
            m.indices.len()
        );
        assert_eq!(m.positions, displaced_sphere(100_000, 3).positions, "deterministic");
    }
}
