// Two-level traversal of obvhs's binary BVHs (Bvh2) with plain f32 boxes: the alternative to the
// CWBVH of scene_geometry.wgsl that the bench measures (src/bvh2.rs). The nodes are bound at
// @group(2) (src/bvh2_geometry.rs); the instance table, the ray set-up and the watertight
// triangle test are scene_geometry.wgsl's (@group(1)), so both traversals give the same hits.
// The loop follows obvhs's Bvh2::ray_traverse_dynamic: test both children of an inner node,
// visit the nearer, push the farther (its child pair), and intersect BLAS leaves as soon as
// their box is hit.

import package::bench::bvh2_types::SgBvh2Node;
import package::bench::bvh2_bindings::{bvh2_node_table, bvh2_triangle_table, bvh2_roots};
import package::scene_geometry::{Hit, NO_HIT, SgRay, sg_instance, sg_make_ray, sg_intersect_triangle};
import package::scene_geometry_types::SgTriangle;
import package::texel_table::texel_fetch;

// Node indices on the stack (BVH2_STACK_SIZE on the Rust side): at most one per level, and the
// scene is refused on the CPU if TLAS depth + BLAS depth could exceed it; were it ever exceeded,
// the push is dropped (possible missed hits, no hang).
const BVH2_STACK_SIZE: u32 = 64u;
// Nodes and triangles are texel tables (src/texel_table.rs), as the CWBVH's.
fn bvh2_node(index: u32) -> SgBvh2Node {
    let a = texel_fetch(bvh2_node_table, index, 2u, 0u);
    let b = texel_fetch(bvh2_node_table, index, 2u, 1u);
    return SgBvh2Node(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), b.w);
}

fn bvh2_triangle(index: u32) -> SgTriangle {
    let a = texel_fetch(bvh2_triangle_table, index, 3u, 0u);
    let b = texel_fetch(bvh2_triangle_table, index, 3u, 1u);
    let c = texel_fetch(bvh2_triangle_table, index, 3u, 2u);
    return SgTriangle(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), b.w, bitcast<vec3f>(c.xyz), c.w);
}

// What bvh2_box returns for a missed box (no hit distance reaches it).
const BVH2_MISS: f32 = 3.4028235e38;

// The slab test of obvhs's Aabb::intersect_ray: the entry distance (negative when the origin is
// inside) if the ray hits the box before t_max, else BVH2_MISS.
fn bvh2_box(node: SgBvh2Node, ray: SgRay, t_max: f32) -> f32 {
    let t1 = (node.min - ray.origin) * ray.inv_direction;
    let t2 = (node.max - ray.origin) * ray.inv_direction;
    let lo = min(t1, t2);
    let hi = max(t1, t2);
    let t_near = max(max(lo.x, lo.y), lo.z);
    let t_far = min(min(hi.x, hi.y), hi.z);
    return select(BVH2_MISS, t_near, t_far >= t_near && t_far >= 0.0 && t_near < t_max);
}

// Intersects a BLAS leaf's triangles, shortening `hit`; true if one was hit (the first one found
// ends the leaf when any_hit).
fn bvh2_leaf(ray: SgRay, node: SgBvh2Node, instance: u32, any_hit: bool, hit: ptr<function, Hit>) -> bool {
    var found = false;
    for (var i = 0u; i < node.prim_count; i++) {
        let tri = bvh2_triangle(node.first_index + i);
        let r = sg_intersect_triangle(ray, tri.v0, tri.v1, tri.v2, (*hit).t);
        if r.w > 0.0 {
            *hit = Hit(r.x, instance, tri.primitive, r.yz);
            found = true;
            if any_hit {
                break;
            }
        }
    }
    return found;
}

// A stack entry or the next step: the index of a pair of sibling nodes (a child pair, whose
// parent's box the ray hits: obvhs pushes `first_index` too, so a visited node is never loaded
// twice), or BVH2_ENTER | instance for a TLAS leaf.
const BVH2_ENTER: u32 = 0x80000000u;

// One stack for both levels, as sg_traverse: entering an instance notes the stack size, moves
// the ray into the instance's object space (t unchanged) and goes on at the BLAS root. When the
// stack falls back to that size the world ray is restored.
fn bvh2_traverse(world_origin: vec3f, world_direction: vec3f, t_max: f32, any_hit: bool) -> Hit {
    var hit = Hit(t_max, NO_HIT, NO_HIT, vec2f(0.0));
    let tlas_root = bvh2_roots[0];
    if tlas_root == NO_HIT || !(t_max > 0.0) {
        return hit;
    }
    let world_ray = sg_make_ray(world_origin, world_direction);
    let root = bvh2_node(tlas_root);
    if bvh2_box(root, world_ray, t_max) == BVH2_MISS {
        return hit;
    }
    var ray = world_ray;
    var stack: array<u32, BVH2_STACK_SIZE>;
    var stack_size = 0u;
    var tlas_stack_size = NO_HIT; // NO_HIT while traversing the TLAS
    var instance = NO_HIT;
    var step = select(root.first_index, BVH2_ENTER | root.first_index, root.prim_count != 0u);
    loop {
        if (step & BVH2_ENTER) != 0u {
            // A TLAS leaf holds one instance, and only instances with triangles are in the TLAS.
            instance = step & ~BVH2_ENTER;
            let record = sg_instance(instance);
            let w2o = record.world_to_object;
            ray = sg_make_ray((w2o * vec4f(world_origin, 1.0)).xyz, (w2o * vec4f(world_direction, 0.0)).xyz);
            tlas_stack_size = stack_size;
            let blas_root = bvh2_node(bvh2_roots[1u + record.mesh]);
            if bvh2_box(blas_root, ray, hit.t) != BVH2_MISS {
                if blas_root.prim_count == 0u {
                    step = blas_root.first_index;
                    continue;
                }
                // A BLAS whose root is a leaf (a mesh of a few triangles).
                if bvh2_leaf(ray, blas_root, instance, any_hit, &hit) && any_hit {
                    return hit;
                }
            }
        } else {
            let in_blas = tlas_stack_size != NO_HIT;
            var near = bvh2_node(step);
            var far = bvh2_node(step + 1u);
            var t_near = bvh2_box(near, ray, hit.t);
            var t_far = bvh2_box(far, ray, hit.t);
            if t_near > t_far {
                let t = t_near;
                t_near = t_far;
                t_far = t;
                let n = near;
                near = far;
                far = n;
            }
            // BLAS leaves are intersected at once, the nearer first so that its hit shortens
            // the farther one's test; TLAS leaves are entered as a step.
            var visit_near = t_near != BVH2_MISS;
            if visit_near && in_blas && near.prim_count != 0u {
                if bvh2_leaf(ray, near, instance, any_hit, &hit) && any_hit {
                    return hit;
                }
                visit_near = false;
            }
            var visit_far = t_far != BVH2_MISS && t_far < hit.t;
            if visit_far && in_blas && far.prim_count != 0u {
                if bvh2_leaf(ray, far, instance, any_hit, &hit) && any_hit {
                    return hit;
                }
                visit_far = false;
            }
            let near_step = select(near.first_index, BVH2_ENTER | near.first_index, near.prim_count != 0u);
            let far_step = select(far.first_index, BVH2_ENTER | far.first_index, far.prim_count != 0u);
            if visit_near {
                if visit_far && stack_size < BVH2_STACK_SIZE {
                    stack[stack_size] = far_step;
                    stack_size += 1u;
                }
                step = near_step;
                continue;
            }
            if visit_far {
                step = far_step;
                continue;
            }
        }
        if stack_size == tlas_stack_size {
            tlas_stack_size = NO_HIT;
            ray = world_ray;
        }
        if stack_size == 0u {
            break;
        }
        stack_size -= 1u;
        step = stack[stack_size];
    }
    return hit;
}

// Closest hit with 0 < t < t_max (t in units of direction), as trace_closest.
fn bvh2_trace_closest(origin: vec3f, direction: vec3f, t_max: f32) -> Hit {
    return bvh2_traverse(origin, direction, t_max, false);
}

// True if anything is hit with 0 < t < t_max, as trace_any.
fn bvh2_trace_any(origin: vec3f, direction: vec3f, t_max: f32) -> bool {
    return bvh2_traverse(origin, direction, t_max, true).instance != NO_HIT;
}
