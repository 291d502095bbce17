// The closed-form setting of Sec. 3 (closed_form.rs beside this file), one trial per invocation with its own
// seed: X_j = τ + σ e_j from cf_params.kind's distribution, the jackknife K (Eq. 4) and the
// naive exp(−X̄); the same draws in the same order as the CPU twin.

import package::media::media_rng::{media_rand};
import package::media::media_jackknife::{jackknife};
import package::media::closed_form_bindings::{cf_params, seeds, trials};

const TWO_PI: f32 = 6.283185307179586;

fn error_sample(kind: u32, rng: ptr<function, u32>) -> f32 {
    switch kind {
        case 0u: {
            let u1 = 1.0 - media_rand(rng);
            let u2 = media_rand(rng);
            return sqrt(-2.0 * log(u1)) * cos(TWO_PI * u2);
        }
        case 1u: {
            return sqrt(3.0) * (2.0 * media_rand(rng) - 1.0);
        }
        case 2u: {
            // u = v + 2^−25 − 0.5 on the open interval; 1 − 2|u| exactly, never 0.
            let v = media_rand(rng);
            let up = v >= 0.5;
            let w = select(2.0 * v + 5.9604645e-8, 2.0 * (1.0 - v) - 5.9604645e-8, up);
            return -0.70710678 * select(-1.0, 1.0, up) * log(w);
        }
        default: {
            return -log(1.0 - media_rand(rng)) - 1.0;
        }
    }
}

@compute @workgroup_size(64)
fn closed_form_trials(@builtin(global_invocation_id) id: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= cf_params.count {
        return;
    }
    var rng = seeds[i];
    let x0 = cf_params.tau + cf_params.sigma * error_sample(cf_params.kind, &rng);
    let x1 = cf_params.tau + cf_params.sigma * error_sample(cf_params.kind, &rng);
    trials[i] = vec2f(jackknife(x0, x1), exp(-(0.5 * (x0 + x1))));
}
