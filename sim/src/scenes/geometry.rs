//! Procedural meshes for the built-in scenes. Triangles are wound counter-clockwise seen
//! from the side their normal points to.

use glam::{Vec2, Vec3};
use scene::Mesh;

/// Accumulates vertices and triangles of one mesh.
pub struct MeshBuilder {
    mesh: Mesh,
}

impl MeshBuilder {
    pub fn new(name: &str) -> Self {
        Self { mesh: Mesh { name: name.to_string(), ..Default::default() } }
    }

    pub fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.mesh.positions.push(p);
        self.mesh.normals.push(n.normalize_or(Vec3::Y));
        self.mesh.uvs.push(uv);
        (self.mesh.positions.len() - 1) as u32
    }

    /// A triangle facing `facing` (its winding is flipped when needed).
    pub fn triangle(&mut self, a: u32, b: u32, c: u32, facing: Vec3) {
        let p = &self.mesh.positions;
        let n = (p[b as usize] - p[a as usize]).cross(p[c as usize] - p[a as usize]);
        self.mesh.indices.push(if n.dot(facing) >= 0.0 { [a, b, c] } else { [a, c, b] });
    }

    /// A flat quad given its corners in order around the boundary.
    pub fn quad(&mut self, corners: [Vec3; 4], normal: Vec3) {
        let uvs =
            [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
        let v: Vec<u32> =
            corners.iter().zip(uvs).map(|(p, uv)| self.vertex(*p, normal, uv)).collect();
        self.triangle(v[0], v[1], v[2], normal);
        self.triangle(v[0], v[2], v[3], normal);
    }

    /// Axis-aligned box from `min` to `max` with outward faces (or inward when `inward`).
    pub fn cuboid(&mut self, min: Vec3, max: Vec3, inward: bool) {
        let c = 0.5 * (min + max);
        let h = 0.5 * (max - min);
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = Vec3::ZERO;
                n[axis] = sign;
                let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
                u[(axis + 1) % 3] = h[(axis + 1) % 3];
                v[(axis + 2) % 3] = h[(axis + 2) % 3];
                let f = c + n * h[axis];
                let facing = if inward { -n } else { n };
                self.quad([f - u - v, f + u - v, f + u + v, f - u + v], facing);
            }
        }
    }

    /// UV sphere of radius `radius` centred at the origin, outward faces.
    pub fn sphere(&mut self, radius: f32, segments: u32, rings: u32) {
        let point = |k: u32, j: u32| {
            let (phi, theta) = (
                std::f32::consts::TAU * k as f32 / segments as f32,
                std::f32::consts::PI * j as f32 / rings as f32,
            );
            Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        };
        let mut index = vec![0u32; ((segments + 1) * (rings + 1)) as usize];
        for j in 0..=rings {
            for k in 0..=segments {
                let n = point(k, j);
                index[(j * (segments + 1) + k) as usize] = self.vertex(
                    radius * n,
                    n,
                    Vec2::new(k as f32 / segments as f32, j as f32 / rings as f32),
                );
            }
        }
        let at = |k: u32, j: u32| index[(j * (segments + 1) + k) as usize];
        for j in 0..rings {
            for k in 0..segments {
                let facing = point(k, j) + point(k + 1, j + 1);
                if j > 0 {
                    self.triangle(at(k, j), at(k + 1, j), at(k + 1, j + 1), facing);
                }
                if j + 1 < rings {
                    self.triangle(at(k, j), at(k + 1, j + 1), at(k, j + 1), facing);
                }
            }
        }
    }

    /// Cone with its base disc at y = 0 (radius `radius`) and apex at y = `height`.
    pub fn cone(&mut self, radius: f32, height: f32, segments: u32) {
        let apex = Vec3::new(0.0, height, 0.0);
        let ring = |k: u32| {
            let a = std::f32::consts::TAU * k as f32 / segments as f32;
            (a, Vec3::new(radius * a.cos(), 0.0, radius * a.sin()))
        };
        let side_normal = |a: f32| Vec3::new(height * a.cos(), radius, height * a.sin());
        let center = self.vertex(Vec3::ZERO, Vec3::NEG_Y, Vec2::splat(0.5));
        for k in 0..segments {
            let ((a0, p0), (a1, p1)) = (ring(k), ring(k + 1));
            let am = 0.5 * (a0 + a1);
            let u0 = k as f32 / segments as f32;
            let u1 = (k + 1) as f32 / segments as f32;
            let i0 = self.vertex(p0, side_normal(a0), Vec2::new(u0, 1.0));
            let i1 = self.vertex(p1, side_normal(a1), Vec2::new(u1, 1.0));
            let ia = self.vertex(apex, side_normal(am), Vec2::new(0.5 * (u0 + u1), 0.0));
            self.triangle(i0, i1, ia, side_normal(am));
            let b0 =
                self.vertex(p0, Vec3::NEG_Y, Vec2::new(0.5 + 0.5 * a0.cos(), 0.5 + 0.5 * a0.sin()));
            let b1 =
                self.vertex(p1, Vec3::NEG_Y, Vec2::new(0.5 + 0.5 * a1.cos(), 0.5 + 0.5 * a1.sin()));
            self.triangle(center, b0, b1, Vec3::NEG_Y);
        }
    }

    /// A thin tube with a triangular cross-section along a polyline (a hair strand).
    pub fn strand(&mut self, points: &[Vec3], radius: f32) {
        const SIDES: usize = 3;
        let mut rings: Vec<[u32; SIDES]> = Vec::with_capacity(points.len());
        for (k, p) in points.iter().enumerate() {
            let t = if k + 1 < points.len() { points[k + 1] - *p } else { *p - points[k - 1] }
                .normalize();
            let helper = if t.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
            let n1 = t.cross(helper).normalize();
            let n2 = t.cross(n1);
            let mut ring = [0u32; SIDES];
            for (s, r) in ring.iter_mut().enumerate() {
                let a = std::f32::consts::TAU * s as f32 / SIDES as f32;
                let n = n1 * a.cos() + n2 * a.sin();
                *r = self.vertex(*p + n * radius, n, Vec2::new(s as f32 / SIDES as f32, k as f32));
            }
            rings.push(ring);
        }
        for w in rings.windows(2) {
            for s in 0..SIDES {
                let (a, b) = (w[0][s], w[0][(s + 1) % SIDES]);
                let (c, d) = (w[1][s], w[1][(s + 1) % SIDES]);
                let mid = |i: u32| self.mesh.positions[i as usize];
                let center = 0.25 * (mid(a) + mid(b) + mid(c) + mid(d));
                let axis_point =
                    0.5 * (points_center(&self.mesh, w[0]) + points_center(&self.mesh, w[1]));
                let outward = center - axis_point;
                self.triangle(a, b, d, outward);
                self.triangle(a, d, c, outward);
            }
        }
    }

    pub fn build(self) -> Mesh {
        self.mesh
    }
}

fn points_center(mesh: &Mesh, ring: [u32; 3]) -> Vec3 {
    ring.iter().map(|&i| mesh.positions[i as usize]).sum::<Vec3>() / 3.0
}

/// A 1 x 1 quad in the XZ plane facing +Y, centred on the origin.
pub fn unit_quad(name: &str) -> Mesh {
    let mut b = MeshBuilder::new(name);
    b.quad(
        [
            Vec3::new(-0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, 0.5),
            Vec3::new(-0.5, 0.0, 0.5),
        ],
        Vec3::Y,
    );
    b.build()
}

/// A unit cube centred on the origin, faces outward.
pub fn unit_cube(name: &str) -> Mesh {
    let mut b = MeshBuilder::new(name);
    b.cuboid(Vec3::splat(-0.5), Vec3::splat(0.5), false);
    b.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum of (face normal x area): zero for a closed surface, and every winding normal
    /// agrees with the vertex normals.
    fn check_closed_and_consistent(mesh: &Mesh) {
        let mut total = Vec3::ZERO;
        for t in &mesh.indices {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = (b - a).cross(c - a);
            total += n;
            let shading: Vec3 = t.iter().map(|&i| mesh.normals[i as usize]).sum();
            assert!(
                n.dot(shading) > 0.0,
                "{}: triangle {t:?} wound against its normals",
                mesh.name
            );
        }
        assert!(total.length() < 1e-3, "{}: not closed, net area vector {total}", mesh.name);
    }

    #[test]
    fn generated_meshes_are_closed_and_wound_outward() {
        check_closed_and_consistent(&unit_cube("cube"));
        let mut b = MeshBuilder::new("cone");
        b.cone(0.5, 1.0, 24);
        check_closed_and_consistent(&b.build());
        let q = unit_quad("quad");
        assert_eq!(q.indices.len(), 2);
        let [a, b, c] = q.indices[0].map(|i| q.positions[i as usize]);
        assert!((b - a).cross(c - a).y > 0.0);
    }
}
