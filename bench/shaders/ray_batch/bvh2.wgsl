// The ray batch's traversal (module package::ray_batch::trace): the BVH2 of bvh2_traversal.wgsl.

import package::scene_geometry::Hit;
import package::bench::bvh2_traversal::{bvh2_trace_any, bvh2_trace_closest};

fn batch_closest(origin: vec3f, direction: vec3f, t_max: f32) -> Hit {
    return bvh2_trace_closest(origin, direction, t_max);
}

fn batch_any(origin: vec3f, direction: vec3f, t_max: f32) -> bool {
    return bvh2_trace_any(origin, direction, t_max);
}
