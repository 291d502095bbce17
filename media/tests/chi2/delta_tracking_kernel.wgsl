// Test kernel of media/tests/chi2_free_flight.rs: delta tracking (media_tracking.wgsl, the
// volume path tracer's free-flight sampler) along one segment of the medium bound at @group(0),
// drawn `count` times, each with its own stream of the media PCG.
// params[0] = (origin, t0), params[1] = (dir, t1) in the medium's texel space (RaySegment),
// params[2] = (count, seed, -, -) as u32 bits. result[i] = (t, escaped, -, -): t the first real
// collision, escaped = 1 when the ray left the segment (t = BIG).

import package::media::types::{RaySegment};
import package::media::media_rng::{media_image_seed};
import package::media::media_grid::{BIG};
import package::media::media_tracking::{delta_tracking};
import package::media::chi2_bindings::{params, result};

const ROW: u32 = 2097152u; // invocations per row of the dispatch (32768 workgroups of 64)

@compute @workgroup_size(64)
fn delta_tracking_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * ROW;
    if i >= bitcast<u32>(params[2].x) {
        return;
    }
    var rng = media_image_seed(bitcast<u32>(params[2].y), 0u, i, 0u);
    let s = RaySegment(params[0].xyz, params[0].w, params[1].xyz, params[1].w);
    let t = delta_tracking(s, &rng);
    result[i] = vec4f(select(t, 0.0, t == BIG), select(0.0, 1.0, t == BIG), 0.0, 0.0);
}
