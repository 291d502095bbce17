//! Watertight ray-triangle intersection (Woop, Benthin & Wald 2013), in f32.
//!
//! The ray is sheared so that it points along +z; the three 2D edge functions are then evaluated
//! the same way for an edge shared by two triangles, so a ray through a shared edge hits at least
//! one of them (no cracks). The WGSL twin is `sg_intersect_triangle` in scene_geometry.wgsl: the
//! same operations in the same order, so CPU and GPU agree up to fused multiply-adds.
//! (The paper's f64 fallback for edge functions that round to exactly zero is left out: WGSL has
//! no portable f64; such a ray counts as on the edge, which keeps the test watertight.)

use glam::{Vec2, Vec3};

/// Per-ray constants of the watertight test: the axis permutation and the shear.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub origin: Vec3,
    /// (kx, ky, kz): kz is the dominant axis of the direction; kx, ky keep the winding.
    pub axes: [usize; 3],
    /// (Sx, Sy, Sz) = (d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz]).
    pub shear: Vec3,
}

impl WatertightRay {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        let a = direction.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let inv = 1.0 / direction[kz];
        Self {
            origin,
            axes: [kx, ky, kz],
            shear: Vec3::new(direction[kx] * inv, direction[ky] * inv, inv),
        }
    }
}

/// The hit `(t, (u, v))` with `0 < t < t_max`, where `u`, `v` weight vertices 1 and 2; `t` is in
/// units of the ray direction the [`WatertightRay`] was made from.
pub fn intersect_triangle(
    ray: &WatertightRay,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
    t_max: f32,
) -> Option<(f32, Vec2)> {
    let [kx, ky, kz] = ray.axes;
    let s = ray.shear;
    let a = v0 - ray.origin;
    let b = v1 - ray.origin;
    let c = v2 - ray.origin;
    let ax = a[kx] - s.x * a[kz];
    let ay = a[ky] - s.y * a[kz];
    let bx = b[kx] - s.x * b[kz];
    let by = b[ky] - s.y * b[kz];
    let cx = c[kx] - s.x * c[kz];
    let cy = c[ky] - s.y * c[kz];
    // Scaled barycentrics of vertices 0, 1, 2 (2D edge functions).
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let az = s.z * a[kz];
    let bz = s.z * b[kz];
    let cz = s.z * c[kz];
    let t = (u * az + v * bz + w * cz) / det;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    Some((t, Vec2::new(v / det, w / det)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const V0: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const V1: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    const V2: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    #[test]
    fn hits_with_distance_and_barycentrics() {
        let ray = WatertightRay::new(Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -2.0));
        let (t, uv) = intersect_triangle(&ray, V0, V1, V2, f32::INFINITY).expect("hit");
        assert!((t - 1.0).abs() < 1e-6, "t = {t}");
        assert!((uv - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-6, "uv = {uv}");
        // From behind too (no culling), and t_max / t > 0 respected.
        let back = WatertightRay::new(Vec3::new(0.25, 0.5, -1.0), Vec3::Z);
        assert!((intersect_triangle(&back, V0, V1, V2, 10.0).unwrap().0 - 1.0).abs() < 1e-6);
        assert!(intersect_triangle(&back, V0, V1, V2, 1.0).is_none());
        let away = WatertightRay::new(Vec3::new(0.25, 0.5, 1.0), Vec3::Z);
        assert!(intersect_triangle(&away, V0, V1, V2, 10.0).is_none());
    }

    #[test]
    fn misses_outside_and_shared_edge_has_no_crack() {
        let outside = WatertightRay::new(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z);
        assert!(intersect_triangle(&outside, V0, V1, V2, 10.0).is_none());
        // Two triangles sharing the diagonal of the unit square; rays exactly through it.
        let v3 = Vec3::new(1.0, 1.0, 0.0);
        for i in 1..100 {
            let x = i as f32 / 100.0;
            let ray = WatertightRay::new(
                Vec3::new(x, 1.0 - x, 1.0) + Vec3::new(0.3, -0.2, 0.0),
                Vec3::new(-0.3, 0.2, -1.0),
            );
            let a = intersect_triangle(&ray, V0, V1, V2, 10.0);
            let b = intersect_triangle(&ray, V1, v3, V2, 10.0);
            assert!(a.is_some() || b.is_some(), "crack at x = {x}");
        }
    }
}
