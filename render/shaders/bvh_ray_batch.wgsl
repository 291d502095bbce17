// Traces a buffer of rays through the scene geometry (scene_geometry.wgsl is prepended):
// closest hits, any-hit flags and hit attributes, for tests and the traversal benchmark.

import package::scene_geometry::{Hit, NO_HIT, previous_world_position, surface_point, trace_any, trace_closest, triangle_world_vertices};

struct RayQuery { origin: vec3f, t_max: f32, direction: vec3f, sg_pad: u32 }

struct HitRecord {
    t: f32,
    instance: u32,
    primitive: u32,
    any_hit: u32,
    barycentrics: vec2f,
    sg_pad: vec2f,
}

struct PointRecord {
    position: vec4f,
    geometric_normal: vec4f,
    shading_normal: vec4f,
    uv: vec2f,
    material: u32,
    sg_pad: u32,
    previous_position: vec4f,
    triangle: array<vec4f, 3>,  // triangle_world_vertices
}

struct BatchParams { count: u32, row_pitch: u32, sg_pad: vec2u }

@group(0) @binding(0) var<storage, read> rays: array<RayQuery>;
@group(0) @binding(1) var<storage, read_write> hits: array<HitRecord>;
@group(0) @binding(2) var<storage, read_write> points: array<PointRecord>;
@group(0) @binding(3) var<uniform> params: BatchParams;

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
    let h = trace_closest(r.origin, r.direction, r.t_max);
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
    hits[i].any_hit = select(0u, 1u, trace_any(r.origin, r.direction, r.t_max));
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
