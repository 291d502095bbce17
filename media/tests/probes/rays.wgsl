// One estimate per segment with the segment's own seed (tests/probes/estimator_pass.rs): what the
// GPU-vs-CPU tests compare, estimate by estimate.

import package::media::media_grid::{media_lookups};
import package::media::media_estimators::{estimate_transmittance};
import package::media::rays_bindings::{ray_params, rays, results, seeds};

@compute @workgroup_size(64)
fn estimate_rays(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= ray_params.count {
        return;
    }
    var rng = seeds[i];
    media_lookups = 0u;
    let v = estimate_transmittance(rays[i], ray_params.kind, ray_params.samples, ray_params.multiplier, &rng);
    results[i] = vec2u(bitcast<u32>(v), media_lookups);
}
