// The SSS pass's noise-free irradiance (sss::direct; CPU twin direct.rs): the thesis's deferred
// irradiance B(p) (UE4's deferred direct lighting), for the pixel-centre ray's hit: the sum over
// the analytic lights of E_l cos θ V / π, V an exact (binary) shadow ray. Lambert radiance
// divided by the albedo, the demodulated irradiance the pass scatters. Point and spot lights
// are deltas; a directional light counts as the delta along its axis (its disc's angular radius
// is ignored: no soft shadow). Emissive triangles and the environment add nothing (the thesis's
// lights are point, spot and directional). No random number is drawn.

import package::scene_bindings::{frame};
import package::scene_features::{HAS_ANALYTIC_LIGHTS};
import package::scene_tables::{light};
import package::scene_geometry::{NO_HIT, surface_point, trace_any, trace_closest};
import package::pt_lights::{FAR, LIGHT_DIRECTIONAL, sample_analytic_light};
import package::pt_scene::{camera_ray_direction, offset_origin, orient};
import package::sss_direct_bindings::{direct_out};
import package::kernel::{outside_image};

const INV_PI: f32 = 0.31830987;

@compute @workgroup_size(8, 8, 1)
fn sss_direct(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let pixel = id.y * frame.width + id.x;
    let origin = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, vec2f(id.xy) + 0.5);
    let hit = trace_closest(origin, dir, FAR);
    var e = vec3f(0.0);
    if HAS_ANALYTIC_LIGHTS && hit.instance != NO_HIT {
        let sp = surface_point(hit, origin, dir);
        let sh = orient(sp, -dir);
        for (var i = 0u; i < frame.analytic_lights; i++) {
            let l = light(i);
            var wi: vec3f;
            var dist: f32;
            var weight: vec3f;
            if l.kind == LIGHT_DIRECTIONAL {
                wi = -normalize(l.p1);
                dist = FAR;
                weight = l.radiance;
            } else {
                // Point and spot: deltas, u is not read.
                let s = sample_analytic_light(l, sp.position, vec2f(0.5));
                wi = s.wi;
                dist = s.dist;
                weight = s.weight;
            }
            let cos_s = dot(sh.ns, wi);
            if dot(wi, sh.ng) <= 0.0 || cos_s <= 0.0 || max(weight.x, max(weight.y, weight.z)) <= 0.0 {
                continue;
            }
            if trace_any(offset_origin(sp.position, sh.ng, wi), wi, dist * (1.0 - 1.0e-4)) {
                continue;
            }
            e += weight * cos_s;
        }
    }
    direct_out[pixel] = vec4f(e * INV_PI, 0.0);
}
