//! Jackknife function estimation for any m ≥ 2 (Sec. 5.1, Thm. 2; Gray et al. 1973): from m
//! i.i.d. normal estimates X_0..X_{m−1} of τ, the UMVU estimate of an analytic g(τ) is Eq. 6,
//! G = Σ_j Γ(a)/Γ(a + j) (−1)^j g^{(2j)}(X̄)/j! (S²/4)^j with a = (m − 1)/2, X̄ the sample
//! mean and S² the biased sample variance (divided by m). For g = exp(−τ) every even derivative
//! is exp(−X̄) and G is Eq. 3, K = exp(−X̄) ₀F₁(; a; −S²/4) (Γ(a)(2/S)^{a−1} J_{a−1}(S) is that
//! series). In f64: the reference of the tests (Table 1); the shaders' f32 twin is
//! `jackknife::jackknife_estimates`.

/// (X̄, S²): the sample mean and the biased sample variance of Thm. 1 (two passes: S² is a
/// difference of nearly equal numbers in one).
pub fn mean_and_variance(x: &[f64]) -> (f64, f64) {
    let m = x.len() as f64;
    let mean = x.iter().sum::<f64>() / m;
    (mean, x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / m)
}

/// Eq. 6 for m estimates with mean `mean` and biased variance `s2`; `even_derivative(j, x)` is
/// g^{(2j)}(x). Summed until a term (past the series' largest) falls below 1e-17 of the sum.
pub fn jackknife_function(
    m: usize,
    mean: f64,
    s2: f64,
    even_derivative: impl Fn(usize, f64) -> f64,
) -> f64 {
    assert!(m >= 2, "Eq. 6 needs m >= 2 estimates (S² of one estimate is 0)");
    let a = 0.5 * (m as f64 - 1.0);
    let z = -0.25 * s2;
    let mut sum = even_derivative(0, mean);
    // c_j = Γ(a)/Γ(a + j) (−S²/4)^j / j!
    let mut c = 1.0;
    for j in 1..512 {
        let jf = j as f64;
        c *= z / (jf * (a + jf - 1.0));
        let term = c * even_derivative(j, mean);
        sum += term;
        if jf * (a + jf - 1.0) > z.abs() && term.abs() <= 1e-17 * sum.abs() {
            break;
        }
    }
    sum
}

/// Eq. 3: the UMVU estimate of exp(−τ) from m ≥ 2 i.i.d. normal optical depths.
pub fn jackknife_transmittance_m(x: &[f64]) -> f64 {
    let (mean, s2) = mean_and_variance(x);
    jackknife_function(x.len(), mean, s2, |_, v| (-v).exp())
}
