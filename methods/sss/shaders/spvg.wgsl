// SPVG (eqs. 4.3, 4.4, 4.9-4.12) and the control variates' EMC and coefficient (eqs. 6.16,
// 6.21); twins of src/spvg.rs and src/control_variates.rs.

struct SpvgParams {
    alpha0: f32,
    kappa: f32,
    sigma0_sq: f32,
    n_min: u32,
    n_max: u32,
}

// History H read for this frame: eq. 4.11 (α = 1 on disocclusion) and eq. 4.12 (σ̂² = σ0²).
struct SpvgState {
    alpha: f32,
    sigma2: f32,
    nbar: f32,
    mu: f32,
    valid: bool,
}

// h = (μ, σ², n̄, valid).
fn spvg_state(h: vec4f, p: SpvgParams) -> SpvgState {
    if h.w > 0.5 {
        return SpvgState(p.alpha0, h.y, h.z, h.x, true);
    }
    return SpvgState(1.0, p.sigma0_sq, f32(p.n_min), 0.0, false);
}

fn spvg_sample_count(st: SpvgState, p: SpvgParams) -> u32 {
    let k = 2.0 / st.alpha - 1.0;
    let ratio = st.sigma2 / p.sigma0_sq;
    let expected = ratio * st.nbar;
    let delta = (ratio - 1.0) * st.nbar * (k - 1.0);
    let n = clamp(p.kappa * delta + expected, f32(p.n_min), f32(p.n_max));
    return u32(floor(n + 0.5));
}

fn spvg_update(st: SpvgState, p: SpvgParams, value: f32, n: u32) -> vec4f {
    if !st.valid {
        return vec4f(value, p.sigma0_sq, f32(n), 1.0);
    }
    let a = st.alpha;
    let diff = value - st.mu;
    return vec4f((1.0 - a) * st.mu + a * value, (1.0 - a) * st.sigma2 + a * (1.0 - a) * diff * diff, (1.0 - a) * st.nbar + a * f32(n), 1.0);
}

// j = (ζ_f, ζ_g, Cov(f̄, ḡ), Var(ḡ)).
fn cv_update(j: vec4f, alpha: f32, f: f32, g: f32) -> vec4f {
    let df = f - j.x;
    let dg = g - j.y;
    return vec4f((1.0 - alpha) * j.x + alpha * f, (1.0 - alpha) * j.y + alpha * g, (1.0 - alpha) * j.z + alpha * (1.0 - alpha) * df * dg, (1.0 - alpha) * j.w + alpha * (1.0 - alpha) * dg * dg);
}

fn cv_coefficient(j: vec4f, eps_a: f32, a0: f32, f: f32, g: f32) -> f32 {
    let a = (j.z + eps_a) / (j.w + eps_a);
    var upper = a0;
    if g > 0.0 {
        upper = a0 + f / g;
    }
    return clamp(a, 0.0, upper);
}
