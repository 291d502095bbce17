//! CWBVH construction over obvhs, and the property traversal rests on: every primitive lies in
//! every quantized box on its path from the root.
//!
//! This is obvhs's `build_cwbvh` helper (PLOC, reinsertion, collapse to 8-wide nodes) without its
//! debug-build self-check. That check compares bounds with an absolute tolerance of 1e-5, so in
//! debug builds it panicked on valid geometry far from the origin and, the other way round, never
//! runs in release, where f32 quantization really can leave geometry outside its box: a mesh
//! spanning 2^41 whose cube sits at 0.5 gets a child box starting at 0 (the quantized offset
//! rounds up). [`first_uncovered`] checks the property itself, in every build, at f32 precision.

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
/// path from the root, as `inside(primitive, box)` judges; `None` when every box holds its
/// primitives. A ray reaches a primitive only through every box on that path, so such a point
/// could be missed.
pub fn first_uncovered(bvh: &CwBvh, inside: impl Fn(u32, &Aabb) -> bool) -> Option<u32> {
    if bvh.nodes.is_empty() {
        return None;
    }
    let mut stack = vec![(0usize, Aabb::LARGEST)];
    while let Some((n, enclosing)) = stack.pop() {
        let node = &bvh.nodes[n];
        for ch in 0..8 {
            if node.is_child_empty(ch) {
                continue;
            }
            let b = node.child_aabb(ch).intersection(&enclosing);
            if node.is_leaf(ch) {
                let (first, count) = node.child_primitives(ch);
                for k in first..first + count {
                    let p = bvh.primitive_indices[k as usize];
                    if !inside(p, &b) {
                        return Some(p);
                    }
                }
            } else {
                stack.push((node.child_node_index(ch) as usize, b));
            }
        }
    }
    None
}

/// Whether `point` is in `b`, up to a few units in the last place of the numbers compared (the
/// precision of the slab tests traversal does with them).
pub fn contains(b: &Aabb, point: Vec3A) -> bool {
    let tolerance = |bound: Vec3A| point.abs().max(bound.abs()) * 4.0 * f32::EPSILON;
    point.cmpge(b.min - tolerance(b.min)).all() && point.cmple(b.max + tolerance(b.max)).all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::triangle::Triangle;

    fn cube(far: f32) -> Vec<Triangle> {
        // Twelve small triangles on a unit cube's corners, and one reaching out to `far`.
        let corner = |i: u32| {
            Vec3A::new((i & 1) as f32 - 0.5, ((i >> 1) & 1) as f32 - 0.5, (i >> 2) as f32 - 0.5)
        };
        let mut tris: Vec<Triangle> = (0..8)
            .map(|i| Triangle { v0: corner(i), v1: corner(i ^ 1), v2: corner(i ^ 2) })
            .collect();
        tris.push(Triangle { v0: Vec3A::new(far, -0.5, 0.5), v1: corner(5), v2: corner(7) });
        tris
    }

    fn uncovered(tris: &[Triangle]) -> Option<u32> {
        let bvh = build_cwbvh(tris, BvhBuildParams::medium_build());
        first_uncovered(&bvh, |p, b| {
            let t = &tris[p as usize];
            [t.v0, t.v1, t.v2].iter().all(|v| contains(b, *v))
        })
    }

    #[test]
    fn boxes_hold_a_mesh_of_ordinary_extent() {
        for far in [-2.0, -1e3, -1e6] {
            assert_eq!(uncovered(&cube(far)), None, "far vertex at {far}");
        }
    }

    /// 2^41 next to features of 0.5: the quantized offset of the cube's box rounds past them.
    #[test]
    fn quantization_beyond_f32_precision_is_found() {
        let far = -(2f32.powi(41));
        assert!(uncovered(&cube(far)).is_some());
    }

    #[test]
    fn a_shrunken_box_is_found() {
        let tris = cube(-2.0);
        let mut bvh = build_cwbvh(&tris, BvhBuildParams::medium_build());
        let inside = |bvh: &CwBvh| {
            first_uncovered(bvh, |p, b| {
                let t = &tris[p as usize];
                [t.v0, t.v1, t.v2].iter().all(|v| contains(b, *v))
            })
        };
        assert_eq!(inside(&bvh), None);
        // Raise one child's quantized minimum: its primitives fall outside.
        let node = &mut bvh.nodes[0];
        let ch = (0..8).find(|&c| !node.is_child_empty(c)).unwrap();
        node.child_min_x[ch] = node.child_max_x[ch];
        assert!(inside(&bvh).is_some());
    }
}
