// The ray batch's traversal (module package::ray_batch::trace): the CWBVH of scene_geometry.wgsl.

import package::scene_geometry::{Hit, trace_any, trace_closest};

fn batch_closest(origin: vec3f, direction: vec3f, t_max: f32) -> Hit {
    return trace_closest(origin, direction, t_max);
}

fn batch_any(origin: vec3f, direction: vec3f, t_max: f32) -> bool {
    return trace_any(origin, direction, t_max);
}
