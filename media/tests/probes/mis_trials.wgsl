// The closed-form MIS setting of mis_trial.rs (beside this file), one trial per invocation with its
// own seed:
// the same draws in the same order as the CPU reference.

import package::media::media_rng::{media_rand};
import package::media::media_jackknife::{jackknife};
import package::media::media_mis::{equiangular_from_foot, equiangular_pdf, equiangular_sample, mis_eq10, mis_eq9, mis_free_flight, mis_jackknife, mis_miller, mis_naive, mis_other};
import package::media::mis_trials_bindings::{mis_params, seeds, trials};

const TAU: f32 = 6.283185307179586;

fn normal(rng: ptr<function, u32>) -> f32 {
    let u1 = 1.0 - media_rand(rng);
    let u2 = media_rand(rng);
    return sqrt(-2.0 * log(u1)) * cos(TAU * u2);
}

fn normal_pair(tau: f32, rng: ptr<function, u32>) -> vec2f {
    let x0 = tau + mis_params.sigma_rel * tau * normal(rng);
    let x1 = tau + mis_params.sigma_rel * tau * normal(rng);
    return vec2f(x0, x1);
}

fn ratio_tracking(len: f32, rng: ptr<function, u32>) -> f32 {
    var t = 0.0;
    var tr = 1.0;
    loop {
        t += -log(1.0 - media_rand(rng)) / mis_params.majorant;
        if t >= len {
            return tr;
        }
        tr *= 1.0 - mis_params.mu / mis_params.majorant;
    }
    return tr;
}

fn ls(t: f32) -> f32 {
    let x = t - mis_params.delta;
    return 1.0 / (mis_params.d * mis_params.d + x * x);
}

@compute @workgroup_size(64)
fn mis_trials(@builtin(global_invocation_id) id: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= mis_params.count {
        return;
    }
    var rng = seeds[i];
    let mu = mis_params.mu;
    let eq = equiangular_from_foot(mis_params.delta, mis_params.d, 0.0, mis_params.t_max);
    let t0 = equiangular_sample(eq, media_rand(&rng));
    let t1_free = -log(1.0 - media_rand(&rng)) / mu;
    let inside = t1_free < mis_params.t_max;
    let t1 = min(t1_free, mis_params.t_max);
    let p0_t0 = equiangular_pdf(eq, t0);
    let p0_t1 = equiangular_pdf(eq, t1);
    let ls0 = ls(t0);
    let ls1 = select(0.0, ls(t1), inside);
    let a = normal_pair(mu * t0, &rng);
    let b = normal_pair(mu * t1, &rng);
    let c = normal_pair(mu * t0, &rng);
    let rt_w0 = ratio_tracking(t0, &rng);
    let rt_w1 = ratio_tracking(t1, &rng);
    let rt_t0 = ratio_tracking(t0, &rng);
    let other = mis_other(mu, p0_t0);
    let free = mis_free_flight(mu, p0_t1);
    let free_t0 = mis_free_flight(mu, p0_t0);
    let w0 = vec3f(mis_naive(other, a.x), mis_jackknife(other, a.x, a.y), 1.0 - mis_miller(mu, p0_t0, rt_w0));
    let w1 = vec3f(mis_naive(free, b.x), mis_jackknife(free, b.x, b.y), mis_miller(mu, p0_t1, rt_w1));
    let tr_jack = jackknife(c.x, c.y);
    let eq9 = vec3f(
        mis_eq9(w0.x, tr_jack, mu, p0_t0, ls0, w1.x, ls1),
        mis_eq9(w0.y, tr_jack, mu, p0_t0, ls0, w1.y, ls1),
        mis_eq9(w0.z, rt_t0, mu, p0_t0, ls0, w1.z, ls1),
    );
    let eq10 = vec2f(
        mis_eq10(mis_naive(free_t0, a.x), ls0, w1.x, ls1),
        mis_eq10(mis_jackknife(free_t0, a.x, a.y), ls0, w1.y, ls1),
    );
    trials[2u * i] = vec4f(w1, eq9.x);
    trials[2u * i + 1u] = vec4f(eq9.yz, eq10);
}
