// One volumetric path per (pixel, sample) (media::gpu::VolumePathPass): the path tracer's
// camera ray and random stream (rng_seed of the frame's seed, frame, pixel, sample), its
// radiance into samples[i].

import package::scene_bindings::{frame};
import package::pt_sampling::{rng_next2, rng_seed};
import package::pt_scene::{camera_ray_direction};
import package::media::media_path::{volume_path_radiance};
import package::media::volume_path_bindings::{samples, vp};

@compute @workgroup_size(64)
fn volume_path(@builtin(global_invocation_id) id: vec3u) {
    // Dispatches wider than 65535 workgroups of 64 continue in y.
    let i = id.x + id.y * (65535u * 64u);
    let pixels = frame.width * frame.height;
    if i >= pixels * vp.spp {
        return;
    }
    let pixel = i / vp.spp;
    let sample = vp.first_sample + i % vp.spp;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, pixel, sample);
    let jitter = rng_next2(&rng);
    let dir = camera_ray_direction(frame.camera, vec2f(f32(pixel % frame.width), f32(pixel / frame.width)) + jitter);
    samples[i] = vec4f(volume_path_radiance(frame.camera.position, dir, &rng), 0.0);
}
