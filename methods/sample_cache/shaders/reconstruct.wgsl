// Reconstruction (section 3.3): the mean radiance of the pixel's visible, shaded samples; motion
// from the closest visible sample (where it was last frame), for reprojected metrics. The same
// colour and that sample's primary attributes (TAA's primary.wgsl) also go to ssc_colour and
// ssc_primary, the inputs of a TAA resolve over the cache.

import package::scene_bindings::{frame};
import package::scene_geometry::{Hit, NO_HIT};
import package::taa_types::{TaaPrimary};
import package::taa::primary::{primary_attributes};
import package::sample_cache_bindings::{dst_mask, dst_slots, ssc, ssc_colour, ssc_out, ssc_primary, ssc_work};
import package::sample_cache::storage::{SSC_AUDIT, SSC_BACKGROUND_DEPTH, ssc_background_dir, ssc_hit, ssc_is_background, ssc_pixels, ssc_surface, ssc_visible_slots};
import package::sample_cache::selection::{ssc_verify};
import package::kernel::{outside_image};

@compute @workgroup_size(8, 8, 1)
fn reconstruct_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) {
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
    var closest_hit = vec4u(0u);
    var any_visible = false;
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
        if !ssc_is_background(slot.hit) {
            t = length(ssc_surface(slot.hit).position - eye);
        }
        if t < closest {
            closest = t;
            closest_hit = slot.hit;
            any_visible = true;
        }
    }
    // The closest visible sample's primary attributes (motion: where it was last frame); a
    // pixel without visible samples has no motion and no surface.
    var primary = TaaPrimary(vec3f(0.0), 0.0, vec2f(0.0), NO_HIT, 0.0);
    if any_visible {
        if ssc_is_background(closest_hit) {
            primary = primary_attributes(Hit(0.0, NO_HIT, 0u, vec2f(0.0)), eye, ssc_background_dir(closest_hit));
        } else {
            primary = primary_attributes(ssc_hit(closest_hit), eye, normalize(ssc_surface(closest_hit).position - eye));
        }
    }
    var radiance = frame.environment;
    if count > 0.0 {
        radiance = sum / count;
    }
    ssc_out[p].radiance = vec4f(radiance, 1.0);
    ssc_out[p].motion = primary.motion;
    ssc_colour[p] = vec4f(radiance, 1.0);
    ssc_primary[p] = primary;
}

// Audit (tests and diagnostics, not part of a frame): counts the samples the cache holds as
// visible that a retrace finds occluded: stale visibility, the ghosting of section 5.
@compute @workgroup_size(8, 8, 1)
fn audit_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) || id.z >= ssc.slots {
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
