// Primary-ray transmittance images (media::gpu::ImagePass): one invocation per (pixel, sample),
// the camera ray clipped to the medium's box on the GPU, one estimate with its own stream.

import package::media::media_rng::{media_image_seed};
import package::media::media_grid::{media_lookups, medium_segment};
import package::media::media_estimators::{estimate_transmittance};
import package::media::image_bindings::{directions, image, results};

@compute @workgroup_size(64)
fn transmittance_image(@builtin(global_invocation_id) id: vec3u) {
    // Dispatches wider than 65535 workgroups of 64 continue in y.
    let i = id.x + id.y * (65535u * 64u);
    let pixels = image.width * image.height;
    if i >= pixels * image.spp {
        return;
    }
    let pixel = i / image.spp;
    let sample = i % image.spp;
    var rng = media_image_seed(image.seed, image.frame, pixel, sample);
    media_lookups = 0u;
    let s = medium_segment(image.origin, directions[pixel].xyz, image.t_max);
    var v = 1.0;
    if s.t0 < s.t1 {
        v = estimate_transmittance(s, image.kind, image.samples, image.multiplier, &rng);
    }
    results[i] = vec2u(bitcast<u32>(v), media_lookups);
}
