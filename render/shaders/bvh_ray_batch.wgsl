// Traces a buffer of rays through the scene geometry (imported from scene_geometry.wgsl):
// closest hits, any-hit flags and hit attributes, for tests and the traversal benchmark. The
// traversal is package::ray_batch::trace, which each batch fills: ray_batch/cwbvh.wgsl, or the
// bench's bench/shaders/ray_batch/bvh2.wgsl.

import package::ray_batch_bindings::{rays, hits, points, params};
import package::ray_batch::trace::{batch_any, batch_closest};
import package::scene_geometry::{Hit, NO_HIT, previous_world_position, surface_point, triangle_world_vertices};

fn ray_index(id: vec3u) -> u32 {
    return id.x + id.y * params.row_pitch;
}

@compute @workgroup_size(64)
fn trace_closest_rays(@builtin(global_invocation_id) id: vec3u) {
    let i = ray_index(id);
    if i >= params.count {
        return;
    }
    let r = rays[i];
    let h = batch_closest(r.origin, r.direction, r.t_max);
    hits[i].t = h.t;
    hits[i].instance = h.instance;
    hits[i].primitive = h.primitive;
    hits[i].barycentrics = h.barycentrics;
}

@compute @workgroup_size(64)
fn trace_any_rays(@builtin(global_invocation_id) id: vec3u) {
    let i = ray_index(id);
    if i >= params.count {
        return;
    }
    let r = rays[i];
    hits[i].any_hit = select(0u, 1u, batch_any(r.origin, r.direction, r.t_max));
}

// Attributes of the closest hit (after trace_closest_rays).
@compute @workgroup_size(64)
fn surface_points(@builtin(global_invocation_id) id: vec3u) {
    let i = ray_index(id);
    if i >= params.count || hits[i].instance == NO_HIT {
        return;
    }
    let r = rays[i];
    let h = Hit(hits[i].t, hits[i].instance, hits[i].primitive, hits[i].barycentrics);
    let p = surface_point(h, r.origin, r.direction);
    points[i].position = vec4f(p.position, 1.0);
    points[i].geometric_normal = vec4f(p.geometric_normal, 0.0);
    points[i].shading_normal = vec4f(p.shading_normal, 0.0);
    points[i].uv = p.uv;
    points[i].material = p.material;
    points[i].previous_position = vec4f(previous_world_position(h), 1.0);
    let v = triangle_world_vertices(h.instance, h.primitive);
    points[i].triangle = array<vec4f, 3>(vec4f(v[0], 1.0), vec4f(v[1], 1.0), vec4f(v[2], 1.0));
}
