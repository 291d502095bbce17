// MIS weights for distance sampling (media::mis): the balance-heuristic weight
// g(τ) = (u0 e^−τ + u1) / (v0 e^−τ + v1) (Eq. 11) estimated naively, by the jackknife
// Re g(X̄ + iS) in Appendix F's real arithmetic (Eq. 12), and as Miller et al.'s ratio-tracking
// weight; the radiance estimates of Eqs. 9 and 10; equiangular sampling (media::equiangular).
// r = (u0, u1, v0, v1).

// w1 = T μ / (p0 + T μ): the weight of free-flight sampling.
fn mis_free_flight(mu: f32, p0: f32) -> vec4f {
    return vec4f(mu, 0.0, mu, p0);
}

// w0 = p0 / (p0 + T μ): the weight of the other strategy.
fn mis_other(mu: f32, p0: f32) -> vec4f {
    return vec4f(0.0, p0, mu, p0);
}

fn mis_naive(r: vec4f, x_mean: f32) -> f32 {
    let e = exp(-x_mean);
    return (r.x * e + r.y) / (r.z * e + r.w);
}

// Re(U/V) = (Re U Re V + Im U Im V) / ((Re V)² + (Im V)²), exp(−(X̄ + iS)) = e^−X̄ (cos S − i sin S).
fn mis_jackknife(r: vec4f, x0: f32, x1: f32) -> f32 {
    let mean = 0.5 * (x0 + x1);
    let s = 0.5 * abs(x0 - x1);
    let e = exp(-mean);
    let re = cos(s) * e;
    let im = -sin(s) * e;
    let re_u = r.x * re + r.y;
    let im_u = r.x * im;
    let re_v = r.z * re + r.w;
    let im_v = r.z * im;
    return (re_u * re_v + im_u * im_v) / (re_v * re_v + im_v * im_v);
}

// μ T_rt / (p0 + μ T_rt), T_rt a ratio-tracking estimate.
fn mis_miller(mu: f32, p0: f32, t_ratio_tracking: f32) -> f32 {
    return mu * t_ratio_tracking / (p0 + mu * t_ratio_tracking);
}

// Eq. 9: unbiased for weight estimates whose expectations sum to 1 (Appendix D).
fn mis_eq9(w0: f32, transmittance_t0: f32, mu_t0: f32, p0_t0: f32, ls0: f32, w1: f32, ls1: f32) -> f32 {
    return w0 * transmittance_t0 * mu_t0 * ls0 / p0_t0 + w1 * ls1;
}

// Eq. 10: both samples weighted by their estimate of g = T μ / (p0 + T μ); slightly biased.
fn mis_eq10(g_t0: f32, ls0: f32, g_t1: f32, ls1: f32) -> f32 {
    return g_t0 * ls0 + g_t1 * ls1;
}

// Equiangular sampling on [a, b] of a ray: (Δ, D, θa, θb).
struct Equiangular {
    delta: f32,
    d: f32,
    theta_a: f32,
    theta_b: f32,
}

fn equiangular_from_foot(delta: f32, d: f32, a: f32, b: f32) -> Equiangular {
    return Equiangular(delta, d, atan((a - delta) / d), atan((b - delta) / d));
}

fn equiangular_new(origin: vec3f, dir: vec3f, light: vec3f, a: f32, b: f32) -> Equiangular {
    let delta = dot(light - origin, dir);
    let d = max(length(light - origin - delta * dir), 1e-6);
    return equiangular_from_foot(delta, d, a, b);
}

fn equiangular_sample(e: Equiangular, xi: f32) -> f32 {
    return e.delta + e.d * tan(e.theta_a + xi * (e.theta_b - e.theta_a));
}

fn equiangular_pdf(e: Equiangular, t: f32) -> f32 {
    let x = t - e.delta;
    return e.d / ((e.theta_b - e.theta_a) * (e.d * e.d + x * x));
}
