// Reconstruction (section 3.3): the mean radiance of the pixel's visible, shaded samples; motion
// from the closest visible sample (where it was last frame), for reprojected metrics.

import package::scene_bindings::{frame};
import package::pt_scene::{project_offset};
import package::sample_cache_bindings::{dst_mask, dst_slots, ssc, ssc_out, ssc_work};
import package::sample_cache::storage::{SSC_AUDIT, SSC_BACKGROUND_DEPTH, ssc_background_dir, ssc_is_background, ssc_pixels, ssc_previous_position, ssc_surface, ssc_visible_slots};
import package::sample_cache::selection::{ssc_verify};

@compute @workgroup_size(8, 8, 1)
fn reconstruct_main(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= ssc.width || id.y >= ssc.height {
        return;
    }
    let pixels = ssc_pixels();
    let n = ssc.slots;
    let p = id.y * ssc.width + id.x;
    let mask = dst_mask[p];
    let vis = ssc_visible_slots(mask);
    let eye = frame.camera.position;
    var sum = vec3f(0.0);
    var count = 0.0;
    var closest = 3.0e38;
    var motion = vec2f(0.0);
    let centre = vec2f(id.xy) + 0.5;
    for (var s = 0u; s < n; s++) {
        if ((vis >> s) & 1u) == 0u {
            continue;
        }
        let slot = dst_slots[s * pixels + p];
        if slot.radiance.w > 0.0 {
            sum += slot.radiance.rgb;
            count += 1.0;
        }
        var t = SSC_BACKGROUND_DEPTH;
        var m = vec2f(0.0);
        if ssc_is_background(slot.hit) {
            let dir = ssc_background_dir(slot.hit);
            m = project_offset(frame.previous_camera, dir) - project_offset(frame.camera, dir);
        } else {
            let now = ssc_surface(slot.hit).position;
            t = length(now - eye);
            let before = project_offset(frame.previous_camera, ssc_previous_position(slot.hit) - frame.previous_camera.position);
            m = before - project_offset(frame.camera, now - eye);
        }
        if t < closest {
            closest = t;
            motion = m;
        }
    }
    var radiance = frame.environment;
    if count > 0.0 {
        radiance = sum / count;
    }
    ssc_out[p].radiance = vec4f(radiance, 1.0);
    ssc_out[p].motion = motion;
}

// Audit (tests and diagnostics, not part of a frame): counts the samples the cache holds as
// visible that a retrace finds occluded: stale visibility, the ghosting of section 5.
@compute @workgroup_size(8, 8, 1)
fn audit_main(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= ssc.width || id.y >= ssc.height || id.z >= ssc.slots {
        return;
    }
    let p = id.y * ssc.width + id.x;
    let mask = dst_mask[p];
    if ((mask >> (id.z + ssc.slots)) & 1u) == 0u {
        return;
    }
    if !ssc_verify(dst_slots[id.z * ssc_pixels() + p].hit) {
        atomicAdd(&ssc_work[SSC_AUDIT], 1u);
    }
}
