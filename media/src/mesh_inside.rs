//! Inside a closed triangle mesh: the winding number of a point, counted as the signed crossings
//! of a ray from it along +x (each triangle crossed counts +1 or −1 by its orientation). For a
//! closed, consistently oriented mesh (`scene::ClosedMesh` checks that) it is 0 outside and
//! nonzero inside.
//!
//! Robust where the ray meets an edge or a vertex: whether the point's (y, z) lies left of an
//! edge is computed once per undirected edge (from its lexicographically smaller end, in f64 from
//! f32 coordinates), so the two faces of an edge always disagree, and a point exactly on an edge's
//! line is decided as if moved by (ε, ε²) in (y, z) (simulation of simplicity). Triangles are
//! binned on a (y, z) grid so that a point tests only those whose projection can hold it.

use glam::{DVec2, Vec3};
use scene::ClosedMesh;

pub struct MeshInside {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// (y, z) bounds of the mesh and the bins over them.
    lo: DVec2,
    hi: DVec2,
    bins: usize,
    /// Per bin, the triangles whose (y, z) bounding box overlaps it.
    cells: Vec<Vec<u32>>,
}

fn yz(p: Vec3) -> DVec2 {
    DVec2::new(p.y as f64, p.z as f64)
}

/// The side of `p` relative to the directed edge a → b: +1 left, −1 right, never 0 (ties broken
/// by the perturbation above; an edge degenerate in (y, z) gets a sign from `signum(0.0)` = 1,
/// the same for both of its faces, whose other edges reject the crossing).
fn side(a: DVec2, b: DVec2, p: DVec2) -> i32 {
    let (s, lo, hi) = if (a.x, a.y) <= (b.x, b.y) { (1, a, b) } else { (-1, b, a) };
    let d = hi - lo;
    let f = d.x * (p.y - lo.y) - d.y * (p.x - lo.x);
    let sign = if f != 0.0 {
        f.signum() as i32
    } else if d.y != 0.0 {
        -(d.y.signum() as i32)
    } else {
        d.x.signum() as i32
    };
    s * sign
}

impl MeshInside {
    pub fn new(mesh: &ClosedMesh) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &p in &mesh.positions {
            lo = lo.min(yz(p));
            hi = hi.max(yz(p));
        }
        let bins = ((mesh.triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 64);
        let mut inside = MeshInside {
            positions: mesh.positions.clone(),
            triangles: mesh.triangles.clone(),
            lo,
            hi,
            bins,
            cells: vec![Vec::new(); bins * bins],
        };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let ps = tri.map(|i| yz(mesh.positions[i as usize]));
            let (a, b) =
                (inside.bin(ps[0].min(ps[1]).min(ps[2])), inside.bin(ps[0].max(ps[1]).max(ps[2])));
            for y in a.0..=b.0 {
                for z in a.1..=b.1 {
                    inside.cells[y + bins * z].push(t as u32);
                }
            }
        }
        inside
    }

    fn bin(&self, p: DVec2) -> (usize, usize) {
        let u = ((p - self.lo) / (self.hi - self.lo).max(DVec2::splat(1e-30)) * self.bins as f64)
            .floor();
        let c = |v: f64| (v.max(0.0) as usize).min(self.bins - 1);
        (c(u.x), c(u.y))
    }

    /// The winding number of the mesh about `p`.
    pub fn winding(&self, p: Vec3) -> i32 {
        let q = yz(p);
        if q.cmplt(self.lo).any() || q.cmpgt(self.hi).any() {
            return 0;
        }
        let (by, bz) = self.bin(q);
        let mut w = 0;
        for &t in &self.cells[by + self.bins * bz] {
            let v = self.triangles[t as usize].map(|i| self.positions[i as usize]);
            let [a, b, c] = v.map(yz);
            let s = [side(a, b, q), side(b, c, q), side(c, a, q)];
            if s[0] == 0 || s[0] != s[1] || s[1] != s[2] {
                continue;
            }
            // Where the +x ray meets the triangle's plane: barycentric weights from the (y, z)
            // areas opposite each vertex.
            let area = |u: DVec2, w: DVec2| (w - u).perp_dot(q - u);
            let (wa, wb, wc) = (area(b, c), area(c, a), area(a, b));
            let sum = wa + wb + wc;
            if sum == 0.0 {
                continue;
            }
            let x = (wa * v[0].x as f64 + wb * v[1].x as f64 + wc * v[2].x as f64) / sum;
            if x > p.x as f64 {
                w += s[0];
            }
        }
        w
    }

    pub fn contains(&self, p: Vec3) -> bool {
        self.winding(p) != 0
    }
}
