// Megakernel path tracer: one thread per pixel, `spp` paths per dispatch, and a separate G-buffer
// entry point that traces the un-jittered pixel-centre ray.

import package::scene_bindings::{frame};
import package::scene_tables::{material};
import package::scene_geometry::{NO_HIT, sg_rays_traced, surface_point, trace_closest};
import package::pt_sampling::{rng_next2, rng_seed};
import package::pt_lights::{FAR};
import package::pt_scene::{base_color_at, camera_ray_direction, orient, primary_motion};
import package::pt_integrator::{NO_STOP, PathPrefix, PathState, path_start, path_vertex};
import package::path_tracer_types::{GBufferTexel, SAMPLES_PER_THREAD};
import package::path_tracer_bindings::{gbuffer, pt_counters, radiance_sum, sample_partials};
import package::kernel::{outside_image};

// Sample `sample_index` of `pixel`: its camera path, and its random-number stream in `rng`.
fn camera_path(pixel: vec2u, sample_index: u32, rng: ptr<function, u32>) -> PathState {
    *rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, pixel.y * frame.width + pixel.x, sample_index);
    let jitter = rng_next2(rng);
    let dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    return path_start(frame.camera.position, dir, 0.0, 0u);
}

// One thread per pixel and chunk of at most SAMPLES_PER_THREAD samples (global id z = chunk).
// The thread advances its path one vertex per loop trip and starts its next sample as soon as a
// path ends (path regeneration), so the lanes that run together (8 per AVX2 instruction on
// lavapipe, a warp on a GPU) do not wait for the longest path among them. A sample's path and
// random numbers do not depend on this order, and the chunk's sum adds the samples in order.
// Few samples per thread keep every invocation short: llvmpipe (Mesa 22) silently ends a shader's
// loops after 65535 iterations in total per invocation, and real GPUs reset a device whose
// dispatch runs too long; spreading samples over z also keeps small images parallel.
@compute @workgroup_size(8, 8, 1)
fn trace_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let first = id.z * SAMPLES_PER_THREAD;
    var sum = vec3f(0.0);
    if first < frame.spp {
        let count = min(SAMPLES_PER_THREAD, frame.spp - first);
        var rng: u32;
        var path = camera_path(id.xy, frame.first_sample + first, &rng);
        var unused: PathPrefix;
        var s = 0u;
        loop {
            path_vertex(&path, NO_STOP, &rng, &unused);
            if path.done {
                sum += path.radiance;
                s += 1u;
                if s >= count {
                    break;
                }
                path = camera_path(id.xy, frame.first_sample + first + s, &rng);
            }
        }
    }
    let pixels = frame.width * frame.height;
    sample_partials[id.z * pixels + id.y * frame.width + id.x] = vec4f(sum, 0.0);
    atomicAdd(&pt_counters[0], sg_rays_traced);
}

// Adds a dispatch's chunks to the running sum in a fixed order (deterministic); w counts samples.
@compute @workgroup_size(8, 8, 1)
fn accumulate_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let pixels = frame.width * frame.height;
    let index = id.y * frame.width + id.x;
    let chunks = (frame.spp + SAMPLES_PER_THREAD - 1u) / SAMPLES_PER_THREAD;
    var sum = vec3f(0.0);
    for (var c = 0u; c < chunks; c++) {
        sum += sample_partials[c * pixels + index].xyz;
    }
    var previous = vec4f(0.0);
    if frame.accumulate != 0u {
        previous = radiance_sum[index];
    }
    radiance_sum[index] = previous + vec4f(sum, f32(frame.spp));
}

// Primary-hit G-buffer from the pixel-centre ray. Misses: depth 0 (the CPU turns it into +inf),
// zero normal and albedo, NO_HIT ids, motion of the direction at infinity.
@compute @workgroup_size(8, 8, 1)
fn gbuffer_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let centre = vec2f(id.xy) + 0.5;
    let origin = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, centre);
    let hit = trace_closest(origin, dir, FAR);
    var g: GBufferTexel;
    g.instance = hit.instance;
    g.primitive = hit.primitive;
    if hit.instance == NO_HIT {
        g.depth = 0.0;
        g.normal = vec3f(0.0);
        g.albedo = vec3f(0.0);
        g.motion = primary_motion(hit, origin, dir, origin);
    } else {
        let sp = surface_point(hit, origin, dir);
        let sh = orient(sp, -dir);
        g.depth = length(sp.position - origin);
        g.normal = sh.ns;
        g.albedo = base_color_at(material(sp.material), sp.uv);
        g.motion = primary_motion(hit, origin, dir, sp.position);
    }
    gbuffer[id.y * frame.width + id.x] = g;
    atomicAdd(&pt_counters[0], sg_rays_traced);
}
