// TAA resolve (Karis 2014, "High-quality temporal supersampling"; Salvi 2016 variance clipping;
// Yang et al. 2020 survey): reproject the history with the pixel's motion vector, reject it where
// the surface was not visible (disocclusion: other instance, depth or normal mismatch at the
// previous position), clamp or clip it to the current 3x3 neighbourhood, blend exponentially.
// The history keeps its length in w: the blend weight is max(alpha, 1 / (length + 1)), so a
// fresh history averages uniformly until it reaches the exponential regime.
// Mirrored on the CPU by src/resolve_cpu.rs (keep them in step).

import package::taa_types::{TaaPrimary};
import package::taa_resolve_bindings::{current, history, previous_primary, primary, resolved, taa};
import package::kernel::{outside_image};

const NO_HIT: u32 = 0xffffffffu;

fn pixel_index(q: vec2i) -> u32 {
    return u32(q.y) * taa.size.x + u32(q.x);
}

// Whether the history at previous pixel `q` shows the same surface as `p` (p's point seen from
// the previous camera at distance p.previous_depth).
fn history_matches(p: TaaPrimary, q: vec2i) -> bool {
    let h = previous_primary[pixel_index(q)];
    if h.instance != p.instance {
        return false;
    }
    if p.instance == NO_HIT {
        return true;
    }
    if abs(h.depth - p.previous_depth) > taa.depth_tolerance * p.previous_depth {
        return false;
    }
    return dot(h.normal, p.normal) >= taa.normal_threshold;
}

// Bilinear history colour at image position `pos` (pixel centres at +0.5), edges clamped.
fn history_bilinear(pos: vec2f) -> vec3f {
    let st = pos - 0.5;
    let base = floor(st);
    let f = st - base;
    let lo = vec2i(0);
    let hi = vec2i(taa.size) - 1;
    let b = vec2i(base);
    let c00 = history[pixel_index(clamp(b, lo, hi))].rgb;
    let c10 = history[pixel_index(clamp(b + vec2i(1, 0), lo, hi))].rgb;
    let c01 = history[pixel_index(clamp(b + vec2i(0, 1), lo, hi))].rgb;
    let c11 = history[pixel_index(clamp(b + vec2i(1, 1), lo, hi))].rgb;
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

// Clips `h` towards the centre of the box [lo, hi] (Playdead's clip_aabb).
fn clip_to_box(lo: vec3f, hi: vec3f, h: vec3f) -> vec3f {
    let centre = 0.5 * (hi + lo);
    let extent = 0.5 * (hi - lo) + vec3f(1.0e-6);
    let v = h - centre;
    let units = abs(v / extent);
    let m = max(units.x, max(units.y, units.z));
    if m > 1.0 {
        return centre + v / m;
    }
    return h;
}

@compute @workgroup_size(8, 8, 1)
fn taa_resolve(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, taa.size.x, taa.size.y) {
        return;
    }
    let index = id.y * taa.size.x + id.x;
    let c = current[index].rgb;
    let p = primary[index];
    let pos = vec2f(id.xy) + 0.5 + p.motion;
    let q = vec2i(floor(pos));
    let inside = pos.x >= 0.0 && pos.y >= 0.0 && pos.x < f32(taa.size.x) && pos.y < f32(taa.size.y);
    if taa.history_valid == 0u || !inside || !history_matches(p, q) {
        resolved[index] = vec4f(c, 1.0);
        return;
    }
    var h = history_bilinear(pos);
    let length = history[pixel_index(q)].w;
    if taa.clamp_mode != 0u {
        var lo = c;
        var hi = c;
        var m1 = vec3f(0.0);
        var m2 = vec3f(0.0);
        var n = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let t = vec2i(id.xy) + vec2i(dx, dy);
                if t.x < 0 || t.y < 0 || t.x >= i32(taa.size.x) || t.y >= i32(taa.size.y) {
                    continue;
                }
                let s = current[pixel_index(t)].rgb;
                lo = min(lo, s);
                hi = max(hi, s);
                m1 += s;
                m2 += s * s;
                n += 1.0;
            }
        }
        if taa.clamp_mode == 1u {
            h = clamp(h, lo, hi);
        } else {
            let mean = m1 / n;
            let sigma = sqrt(max(m2 / n - mean * mean, vec3f(0.0)));
            h = clip_to_box(mean - taa.gamma * sigma, mean + taa.gamma * sigma, h);
        }
    }
    let a = max(taa.alpha, 1.0 / (length + 1.0));
    resolved[index] = vec4f(mix(h, c, a), min(length + 1.0, taa.max_history));
}
