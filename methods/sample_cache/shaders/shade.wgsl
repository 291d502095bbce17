// Shading of cached samples (section 3.3): one path from the sample's surface point towards the
// current camera with the shared integrator, accumulated into the slot's radiance. The blend
// weight is max(1 / (c_s + 1), α_min): a running mean that becomes an exponential average with
// factor α_min once c_s >= 1/α_min - 1 (α_min = `alpha`, or App. C's roughness-dependent one;
// α = 0 keeps the mean).

import package::scene_bindings::{frame};
import package::scene_tables::{material};
import package::scene_geometry::{sg_rays_traced};
import package::pt_sampling::{max_component, rng_next, rng_next2, rng_seed};
import package::pt_bsdf::{bsdf_sample, make_bsdf};
import package::pt_scene::{base_color_at, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance, next_event, path_radiance};
import package::sample_cache_bindings::{dst_slots, ssc, ssc_work};
import package::sample_cache::storage::{SSC_ALL_RAYS, SSC_LIST, SSC_SHADE_COUNT, ssc_background_dir, ssc_is_background, ssc_list_index, ssc_pixels, ssc_surface};

fn ssc_shade(hit: vec4u, rng: ptr<function, u32>) -> vec3f {
    let eye = frame.camera.position;
    if ssc_is_background(hit) {
        return escaped_radiance(ssc_background_dir(hit), 0.0);
    }
    let sp = ssc_surface(hit);
    let d = sp.position - eye;
    let dist = length(d);
    let dir = d / dist;
    let wo = -dir;
    let sh = orient(sp, wo);
    let m = material(sp.material);
    var radiance = emitted_radiance(sp, m, dir, dist, 0.0);
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    radiance += next_event(sp.position, sh, bsdf, wo, rng);
    // Continue as path_radiance does after its camera-ray vertex.
    let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(rng), rng_next2(rng));
    if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 || frame.max_depth == 0u {
        return radiance;
    }
    var throughput = bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
    if 1u >= frame.rr_start_depth {
        let survive = min(max_component(throughput), 0.95);
        if rng_next(rng) >= survive {
            return radiance;
        }
        throughput /= survive;
    }
    return radiance + throughput * path_radiance(offset_origin(sp.position, sh.ng, bs.wi), bs.wi, bs.pdf, 1u, rng);
}

// Minimum blend weight: `alpha`, or App. C's α_min = (1 − α_GGX)·0.5 + α_GGX·0.1 from the
// material's GGX α (make_bsdf's roughness²), so that glossy samples follow the view faster.
fn ssc_alpha_min(hit: vec4u) -> f32 {
    if ssc.roughness_alpha == 0u || ssc_is_background(hit) {
        return ssc.alpha;
    }
    let m = material(ssc_surface(hit).material);
    let a_ggx = make_bsdf(vec3f(0.0), m.metallic, m.roughness, m.specular).alpha;
    return mix(0.5, 0.1, a_ggx);
}

// One thread per entry: dispatched indirectly with the list's length (list_dispatch.wgsl).
@compute @workgroup_size(64, 1, 1)
fn shade_main(@builtin(global_invocation_id) id: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let pixels = ssc_pixels();
    let index = ssc_list_index(id, groups);
    if index >= atomicLoad(&ssc_work[SSC_SHADE_COUNT]) {
        return;
    }
    let entry = atomicLoad(&ssc_work[SSC_LIST + index]);
    let slot = dst_slots[entry];
    // Seeded by (pixel, slot): the list order (atomics) does not change any result.
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, entry % pixels, 0x5a00u + entry / pixels);
    let l = ssc_shade(slot.hit, &rng);
    atomicAdd(&ssc_work[SSC_ALL_RAYS], sg_rays_traced);
    let c = slot.radiance.w;
    let a = max(1.0 / (c + 1.0), ssc_alpha_min(slot.hit));
    dst_slots[entry].radiance = vec4f(mix(slot.radiance.rgb, l, a), c + 1.0);
}
