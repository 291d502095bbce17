// bvh_ray_batch.wgsl's closest and any-hit kernels through the BVH2 traversal
// (bvh2_traversal.wgsl), for the traversal tests and the benchmark's BVH2 against CWBVH.

import package::ray_batch_bindings::{rays, hits, params};
import package::bvh2_traversal::{bvh2_trace_any, bvh2_trace_closest};

@compute @workgroup_size(64)
fn trace_closest_rays_bvh2(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * params.row_pitch;
    if i >= params.count {
        return;
    }
    let r = rays[i];
    let h = bvh2_trace_closest(r.origin, r.direction, r.t_max);
    hits[i].t = h.t;
    hits[i].instance = h.instance;
    hits[i].primitive = h.primitive;
    hits[i].barycentrics = h.barycentrics;
}

@compute @workgroup_size(64)
fn trace_any_rays_bvh2(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * params.row_pitch;
    if i >= params.count {
        return;
    }
    let r = rays[i];
    hits[i].any_hit = select(0u, 1u, bvh2_trace_any(r.origin, r.direction, r.t_max));
}
