//! CWBVH construction over obvhs, and the property traversal rests on: every primitive lies in
//! every quantized box on its path from the root, up to the rounding of the numbers the box is
//! computed from.
//!
//! This is obvhs's `build_cwbvh` helper (PLOC, reinsertion, collapse to 8-wide nodes) without its
//! debug-build self-check, which compares bounds with an absolute tolerance of 1e-5: in debug
//! builds it panicked on valid geometry far from the origin (a mesh spanning 2^41, where f32
//! boxes are only as precise as 2^41's last place), while release builds never run it.
//! [`first_uncovered`] checks the property in every build, at f32 precision.

use glam::Vec3A;
use obvhs::{
    Boundable, BvhBuildParams, aabb::Aabb, bvh2::reinsertion::ReinsertionOptimizer, cwbvh::CwBvh,
    cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh, ploc::PlocBuilder,
};

/// A CWBVH over `primitives` (`params.pre_split` is ignored).
pub fn build_cwbvh<T: Boundable>(primitives: &[T], params: BvhBuildParams) -> CwBvh {
    let mut bvh2 = PlocBuilder::with_capacity(primitives.len()).build(
        params.ploc_search_distance,
        primitives,
        (0..primitives.len() as u32).collect(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false)
}

/// The first primitive (its index as built over) with a point outside a quantized box on its
/// path from the root, as `inside(primitive, box, scale)` judges, `scale` being the largest
/// magnitude per axis of the numbers the boxes on that path were computed from (node origins
/// and bounds); `None` when every box holds its primitives. A ray reaches a primitive only
/// through every box on that path, so such a point could be missed.
pub fn first_uncovered(bvh: &CwBvh, inside: impl Fn(u32, &Aabb, Vec3A) -> bool) -> Option<u32> {
    if bvh.nodes.is_empty() {
        return None;
    }
    let mut stack = vec![(0usize, Aabb::LARGEST, Vec3A::ZERO)];
    while let Some((n, enclosing, scale)) = stack.pop() {
        let node = &bvh.nodes[n];
        let scale = scale.max(Vec3A::from(node.p).abs());
        for ch in 0..8 {
            if node.is_child_empty(ch) {
                continue;
            }
            let child = node.child_aabb(ch);
            let scale = scale.max(child.min.abs()).max(child.max.abs());
            let b = child.intersection(&enclosing);
            if node.is_leaf(ch) {
                let (first, count) = node.child_primitives(ch);
                for k in first..first + count {
                    let p = bvh.primitive_indices[k as usize];
                    if !inside(p, &b, scale) {
                        return Some(p);
                    }
                }
            } else {
                stack.push((node.child_node_index(ch) as usize, b, scale));
            }
        }
    }
    None
}

/// Whether `point` is in `b`, up to a few units in the last place of `scale` (the numbers the
/// box was computed from) and of the point itself: the rounding every slab test has too.
pub fn contains(b: &Aabb, point: Vec3A, scale: Vec3A) -> bool {
    let tolerance = scale.max(point.abs()) * 4.0 * f32::EPSILON;
    point.cmpge(b.min - tolerance).all() && point.cmple(b.max + tolerance).all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::triangle::Triangle;

    fn cube(far: f32) -> Vec<Triangle> {
        // Eight small triangles on a unit cube's corners, and one reaching out to `far`.
        let corner = |i: u32| {
            Vec3A::new((i & 1) as f32 - 0.5, ((i >> 1) & 1) as f32 - 0.5, (i >> 2) as f32 - 0.5)
        };
        let mut tris: Vec<Triangle> = (0..8)
            .map(|i| Triangle { v0: corner(i), v1: corner(i ^ 1), v2: corner(i ^ 2) })
            .collect();
        tris.push(Triangle { v0: Vec3A::new(far, -0.5, 0.5), v1: corner(5), v2: corner(7) });
        tris
    }

    fn uncovered(tris: &[Triangle], bvh: &CwBvh) -> Option<u32> {
        first_uncovered(bvh, |p, b, scale| {
            let t = &tris[p as usize];
            [t.v0, t.v1, t.v2].iter().all(|v| contains(b, *v, scale))
        })
    }

    /// Ordinary meshes, a sphere whose vertices sit on the box planes (coordinates of 1e-8 next
    /// to bounds of 0), and a mesh spanning 2^41 (f32 boxes as precise as 2^41's last place).
    #[test]
    fn boxes_hold_their_primitives() {
        let sphere = crate::bvh::displaced_sphere(5000, 1);
        let sphere: Vec<Triangle> = crate::bvh::mesh_triangles(0, &sphere).unwrap();
        let mut meshes = vec![sphere];
        meshes.extend([-2.0, -1e3, -1e6, -(2f32.powi(41))].map(cube));
        for tris in &meshes {
            let bvh = build_cwbvh(tris, BvhBuildParams::medium_build());
            assert_eq!(uncovered(tris, &bvh), None, "{} triangles", tris.len());
        }
    }

    /// A box raised past its primitives is found, at the root and deeper down.
    #[test]
    fn a_shrunken_box_is_found() {
        let sphere = crate::bvh::displaced_sphere(5000, 1);
        let tris: Vec<Triangle> = crate::bvh::mesh_triangles(0, &sphere).unwrap();
        let bvh = build_cwbvh(&tris, BvhBuildParams::medium_build());
        assert!(bvh.nodes.len() > 2);
        for n in [0, bvh.nodes.len() - 1] {
            let mut broken = bvh.clone();
            let node = &mut broken.nodes[n];
            let ch = (0..8).find(|&c| !node.is_child_empty(c)).unwrap();
            // One quantum up: by the node's quantization step, which is more than rounding.
            assert!(node.child_min_x[ch] < node.child_max_x[ch]);
            node.child_min_x[ch] += 1;
            assert!(uncovered(&tris, &broken).is_some(), "node {n}");
        }
    }
}
