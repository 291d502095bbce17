// TAA input: one path per pixel through the frame's Halton jitter point, with the attributes of
// its own primary hit (primary.wgsl) for the history test of resolve.wgsl.
// Its buffers in @group(2) are declared in src/lib.rs (TRACE_GROUP).

import package::scene_bindings::{frame};
import package::scene_geometry::{sg_rays_traced, trace_closest};
import package::pt_sampling::{rng_seed};
import package::pt_lights::{FAR};
import package::pt_scene::{camera_ray_direction};
import package::pt_integrator::{path_radiance};
import package::taa::primary::{primary_attributes};
import package::taa_trace_bindings::{taa, taa_counters, taa_current, taa_primary};
import package::kernel::{outside_image};

@compute @workgroup_size(8, 8, 1)
fn taa_trace(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let index = id.y * frame.width + id.x;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, index, frame.first_sample);
    let origin = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, vec2f(id.xy) + taa.jitter);
    // The primary ray is traced twice (here and in path_radiance): one ray of a whole path,
    // for keeping the shared integrator untouched.
    let hit = trace_closest(origin, dir, FAR);
    taa_primary[index] = primary_attributes(hit, origin, dir);
    taa_current[index] = vec4f(path_radiance(origin, dir, 0.0, 0u, &rng), 1.0);
    atomicAdd(&taa_counters[0], sg_rays_traced);
}
