// Which cached samples are shaded this frame (sections 3.3 and 3.5). Uniform: one visible sample
// per pixel, round robin (a never-shaded sample first). Adaptive: one sample per 4x4 block as the
// base rate and one of each pixel with no shaded visible sample (ssc_forced_shade), the rest of the budget by importance w = 1 / (1 + c_s) through the log histogram:
// buckets above the threshold all, the threshold bucket by a weighted coin toss.
// The chosen slots are appended to the shade list (compacted work for shade_main).

import package::scene_bindings::{frame};
import package::scene_geometry::{NO_HIT};
import package::pt_sampling::{rng_next, rng_seed};
import package::sample_cache_bindings::{dst_mask, dst_slots, ssc, ssc_work};
import package::sample_cache::storage::{SSC_BASE, SSC_COIN, SSC_HISTOGRAM, SSC_LIST, SSC_SHADE_COUNT, SSC_THRESHOLD, ssc_pixels, ssc_visible_slots};
import package::sample_cache::selection::{ssc_bucket, ssc_forced_shade, ssc_importance, ssc_nth_bit};
import package::kernel::{outside_image};

// One thread: the threshold bucket and its coin probability from the histogram and the budget
// (twin of src/shading_rate.rs `threshold`).
@compute @workgroup_size(1, 1, 1)
fn rates_main() {
    let m = ssc.buckets;
    let budget = max(ssc.shading_budget - f32(atomicLoad(&ssc_work[SSC_BASE])), 0.0);
    var above = 0.0;
    var threshold = 0u;
    var coin = 1.0;
    for (var i = 0u; i < m; i++) {
        let b = m - 1u - i;
        let c = f32(atomicLoad(&ssc_work[SSC_HISTOGRAM + b]));
        if c > 0.0 && above + c >= budget {
            threshold = b;
            coin = (budget - above) / c;
            break;
        }
        above += c;
    }
    atomicStore(&ssc_work[SSC_THRESHOLD], threshold);
    atomicStore(&ssc_work[SSC_COIN], bitcast<u32>(coin));
}

fn ssc_push_shade(entry: u32) {
    let at = atomicAdd(&ssc_work[SSC_SHADE_COUNT], 1u);
    atomicStore(&ssc_work[SSC_LIST + at], entry);
}

@compute @workgroup_size(8, 8, 1)
fn select_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) {
        return;
    }
    let pixels = ssc_pixels();
    let n = ssc.slots;
    let p = id.y * ssc.width + id.x;
    let mask = dst_mask[p];
    let vis = ssc_visible_slots(mask);
    let nv = countOneBits(vis);
    if nv == 0u {
        return;
    }
    if ssc.shading == 0u {
        var chosen = ssc_nth_bit(vis, ssc.frame % nv);
        for (var s = 0u; s < n; s++) {
            if ((vis >> s) & 1u) != 0u && dst_slots[s * pixels + p].radiance.w == 0.0 {
                chosen = s;
                break;
            }
        }
        ssc_push_shade(chosen * pixels + p);
        return;
    }
    let base = ssc_forced_shade(id.xy, p, vis);
    if base != NO_HIT {
        ssc_push_shade(base * pixels + p);
    }
    let threshold = atomicLoad(&ssc_work[SSC_THRESHOLD]);
    let coin = bitcast<f32>(atomicLoad(&ssc_work[SSC_COIN]));
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, p, 0x5e1eu);
    for (var s = 0u; s < n; s++) {
        if ((vis >> s) & 1u) == 0u || s == base {
            continue;
        }
        let b = ssc_bucket(ssc_importance(dst_slots[s * pixels + p].radiance.w));
        let u = rng_next(&rng);
        if b > threshold || (b == threshold && u < coin) {
            ssc_push_shade(s * pixels + p);
        }
    }
}
