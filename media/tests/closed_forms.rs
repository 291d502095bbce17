//! The paper's closed forms on synthetic optical-depth estimates, 10^6 trials each: the
//! jackknife (Eq. 4) is unbiased for normal inputs with V(K) = (exp(σ²) − 1)/2 · exp(−2τ), the
//! naive exp(−X) overestimates by (exp(σ²/2) − 1)·T, and on Fig. 2's other distributions the
//! jackknife's bias is below the naive estimate's (slightly negative on Laplace). Margins are
//! standard errors of the same run (4.5 of them), not tuned constants. The same closed forms
//! hold on the GPU (media_closed_form_trials.wgsl, 10^6 trials each), whose trials equal the
//! CPU twin's (tests/probes/closed_form.rs) on the same random numbers.

mod common;
mod probes;

use common::{C, Moments, normal};
use std::sync::OnceLock;

use media::Pcg;
use media::jackknife::jackknife;
use probes::closed_form::{ErrorDistribution, trial};
use probes::closed_form_pass::{ClosedFormParams, ClosedFormPass};
use render::gpu::Gpu;

const TRIALS: usize = 1_000_000;
const Z: f64 = 4.5;

fn assert_close(what: &str, got: f64, want: f64, se: f64) {
    assert!(
        (got - want).abs() <= Z * se,
        "{what}: {got} vs {want} (|diff| {} > {Z} SE = {})",
        (got - want).abs(),
        Z * se
    );
}

#[test]
fn jackknife_is_unbiased_with_the_closed_form_variance_on_normal_inputs() {
    for (seed, tau, sigma) in [(1u32, 2.0f64, 0.5f64), (2, 1.0, 1.0), (3, 0.5, 0.25)] {
        let mut rng = Pcg::new(seed);
        let mut k = Moments::default();
        for _ in 0..TRIALS {
            let x0 = tau + sigma * normal(&mut rng);
            let x1 = tau + sigma * normal(&mut rng);
            k.add(f64::from(jackknife(x0 as f32, x1 as f32)));
        }
        let t = (-tau).exp();
        assert_close(&format!("E[K] at τ={tau} σ={sigma}"), k.mean(), t, k.se());
        let v = ((sigma * sigma).exp() - 1.0) / 2.0 * (-2.0 * tau).exp();
        assert_close(&format!("V(K) at τ={tau} σ={sigma}"), k.var(), v, k.var_se());
    }
}

#[test]
fn naive_estimate_overestimates_by_the_closed_form() {
    for (seed, tau, sigma) in [(4u32, 2.0f64, 0.5f64), (5, 1.0, 1.0)] {
        let mut rng = Pcg::new(seed);
        let mut l = Moments::default();
        for _ in 0..TRIALS {
            l.add(f64::from((-(tau + sigma * normal(&mut rng)) as f32).exp()));
        }
        let t = (-tau).exp();
        let bias = ((sigma * sigma / 2.0).exp() - 1.0) * t;
        assert_close(&format!("naive bias at τ={tau} σ={sigma}"), l.mean() - t, bias, l.se());
        assert!(l.mean() - t > 10.0 * l.se(), "the bias must be visible at this trial count");
    }
}

/// A zero-mean distribution of optical-depth error: its sampler and its moment generating
/// function M(s) = E[exp(s·e)] at complex s.
struct Dist {
    name: &'static str,
    sample: fn(&mut Pcg) -> f64,
    mgf: fn(C) -> C,
}

// All with standard deviation 1.
const A_UNIFORM: f64 = 1.732_050_807_568_877_2; // √3
const B_LAPLACE: f64 = std::f64::consts::FRAC_1_SQRT_2; // 1/√2

fn distributions() -> [Dist; 3] {
    [
        Dist {
            name: "uniform",
            sample: |r| A_UNIFORM * (2.0 * f64::from(r.next_f32()) - 1.0),
            mgf: |s| {
                let a = s.scale(A_UNIFORM);
                a.sinh().div(a)
            },
        },
        Dist {
            name: "laplace",
            sample: |r| {
                let u = f64::from(r.next_f32()) + 0.5f64.powi(25) - 0.5; // open interval: no infinite tail
                -B_LAPLACE * u.signum() * (1.0 - 2.0 * u.abs()).ln()
            },
            mgf: |s| {
                C::new(1.0, 0.0).div(C::new(1.0, 0.0).add(s.mul(s).scale(-B_LAPLACE * B_LAPLACE)))
            },
        },
        Dist {
            // single-sided: θ(E − 1), E ~ Exp(1), θ = 1
            name: "exponential",
            sample: |r| -(1.0 - f64::from(r.next_f32())).ln() - 1.0,
            mgf: |s| s.scale(-1.0).exp().div(C::new(1.0, 0.0).add(s.scale(-1.0))),
        },
    ]
}

#[test]
fn fig2_jackknife_has_less_bias_than_naive_and_underestimates_on_laplace() {
    let tau = 3.0f64;
    let t = (-tau).exp();
    for (i, d) in distributions().iter().enumerate() {
        // Exact expectations: E[K] = T·M((−1+i)/2)·M((−1−i)/2), E[exp(−X̄)] = T·M(−1/2)².
        let jack_exact = t * (d.mgf)(C::new(-0.5, 0.5)).mul((d.mgf)(C::new(-0.5, -0.5))).re - t;
        let naive_exact = t * (d.mgf)(C::new(-0.5, 0.0)).re.powi(2) - t;
        let mut rng = Pcg::new(100 + i as u32);
        let (mut jack, mut naive) = (Moments::default(), Moments::default());
        for _ in 0..TRIALS {
            let x0 = tau + (d.sample)(&mut rng);
            let x1 = tau + (d.sample)(&mut rng);
            jack.add(f64::from(jackknife(x0 as f32, x1 as f32)));
            naive.add(f64::from((-(0.5 * (x0 + x1)) as f32).exp()));
        }
        assert_close(&format!("{} jackknife bias", d.name), jack.mean() - t, jack_exact, jack.se());
        assert_close(&format!("{} naive bias", d.name), naive.mean() - t, naive_exact, naive.se());
        assert!(
            jack_exact.abs() < naive_exact.abs(),
            "{}: exact |bias| jackknife {jack_exact} vs naive {naive_exact}",
            d.name
        );
        assert!(
            (jack.mean() - t).abs() + Z * jack.se() < (naive.mean() - t).abs(),
            "{}: measured |bias| jackknife {} vs naive {}",
            d.name,
            jack.mean() - t,
            naive.mean() - t
        );
        if d.name == "laplace" {
            assert!(
                jack_exact < 0.0 && jack.mean() - t < -Z * jack.se(),
                "the jackknife underestimates on Laplace: {}",
                jack.mean() - t
            );
        }
    }
}

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

/// 10^6 GPU trials: their moments (K, exp(−X̄)), after checking them against the CPU twin on the
/// same seeds (log and cos may round differently on the GPU: a relative 1e-4 allowance, and at
/// most 1 in 10^4 trials beyond it).
fn gpu_trials(
    pass: &ClosedFormPass,
    dist: ErrorDistribution,
    tau: f64,
    sigma: f64,
    base: u32,
) -> (Moments, Moments) {
    let seeds: Vec<u32> =
        (0..TRIALS as u32).map(|i| i.wrapping_mul(2654435761).wrapping_add(base)).collect();
    let got = pass.run(gpu(), dist, tau as f32, sigma as f32, &seeds).expect("closed-form trials");
    let (mut k, mut naive, mut differ) = (Moments::default(), Moments::default(), 0);
    for (&(gk, gn), &seed) in got.iter().zip(&seeds) {
        let (ck, cn) = trial(dist, tau as f32, sigma as f32, &mut Pcg::new(seed));
        let off = |g: f32, c: f32| !((g - c).abs() <= 1e-5 + 1e-4 * c.abs());
        differ += usize::from(off(gk, ck) || off(gn, cn));
        k.add(f64::from(gk));
        naive.add(f64::from(gn));
    }
    let t = (-tau).exp();
    println!(
        "GPU {dist:?} τ={tau} σ={sigma}: {differ} of {TRIALS} trials differ from the CPU twin; E[K] − T = {:.3e} ± {:.1e}, V(K) = {:.4e} ± {:.1e}, E[exp(−X̄)] − T = {:.3e} ± {:.1e}",
        k.mean() - t,
        k.se(),
        k.var(),
        k.var_se(),
        naive.mean() - t,
        naive.se()
    );
    assert!(
        differ * 10_000 <= TRIALS,
        "{dist:?} τ={tau} σ={sigma}: {differ} of {TRIALS} GPU trials differ from the CPU twin"
    );
    (k, naive)
}

#[test]
fn the_gpu_holds_the_closed_forms_on_the_cpu_twins_random_numbers() {
    assert_eq!(render::gpu_struct::layout_mismatches::<ClosedFormParams>(""), Vec::<String>::new());
    let pass = ClosedFormPass::new(gpu()).expect("closed-form pass compiles");
    for (base, tau, sigma) in [(11u32, 2.0f64, 0.5f64), (12, 1.0, 1.0)] {
        let (k, naive) = gpu_trials(&pass, ErrorDistribution::Normal, tau, sigma, base);
        let t = (-tau).exp();
        assert_close(&format!("GPU E[K] at τ={tau} σ={sigma}"), k.mean(), t, k.se());
        assert_close(
            &format!("GPU V(K) at τ={tau} σ={sigma}"),
            k.var(),
            ((sigma * sigma).exp() - 1.0) / 2.0 * (-2.0 * tau).exp(),
            k.var_se(),
        );
        // The naive estimate's input is X̄ of the two, of variance σ²/2: bias (exp(σ²/4) − 1)·T.
        assert_close(
            &format!("GPU naive bias at τ={tau} σ={sigma}"),
            naive.mean() - t,
            ((sigma * sigma / 4.0).exp() - 1.0) * t,
            naive.se(),
        );
    }
    let tau = 3.0f64;
    let t = (-tau).exp();
    let kinds =
        [ErrorDistribution::Uniform, ErrorDistribution::Laplace, ErrorDistribution::Exponential];
    for (i, (dist, d)) in kinds.into_iter().zip(distributions()).enumerate() {
        let (jack, naive) = gpu_trials(&pass, dist, tau, 1.0, 20 + i as u32);
        let jack_exact = t * (d.mgf)(C::new(-0.5, 0.5)).mul((d.mgf)(C::new(-0.5, -0.5))).re - t;
        let naive_exact = t * (d.mgf)(C::new(-0.5, 0.0)).re.powi(2) - t;
        assert_close(
            &format!("GPU {} jackknife bias", d.name),
            jack.mean() - t,
            jack_exact,
            jack.se(),
        );
        assert_close(
            &format!("GPU {} naive bias", d.name),
            naive.mean() - t,
            naive_exact,
            naive.se(),
        );
        assert!(
            (jack.mean() - t).abs() + Z * jack.se() < (naive.mean() - t).abs(),
            "GPU {}: |bias| jackknife {} vs naive {}",
            d.name,
            jack.mean() - t,
            naive.mean() - t
        );
        if dist == ErrorDistribution::Laplace {
            assert!(
                jack.mean() - t < -Z * jack.se(),
                "GPU: the jackknife underestimates on Laplace: {}",
                jack.mean() - t
            );
        }
    }
}
