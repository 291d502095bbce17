//! MIS weights (Sec. 5.2, Appendix F): the real-arithmetic jackknife weight equals
//! Re g(X̄ + iS) computed with complex numbers; the two strategies' weights sum to 1 for every
//! input (Appendix D); at Fig. 7's (u0, u1, v0, v1) = (1, 0, 1, 1/2) with normal inputs below
//! σ = 1.645τ the jackknife weight has less bias than the naive g(X̄) (10^6 trials each).

mod common;

use common::{C, Moments, normal};
use media::Pcg;
use media::mis::{Ratio, miller_weight};

#[test]
fn real_form_equals_complex_arithmetic() {
    let mut rng = Pcg::new(9);
    for _ in 0..10_000 {
        let r = Ratio {
            u0: rng.next_f32(),
            u1: rng.next_f32(),
            v0: rng.next_f32() + 0.01,
            v1: rng.next_f32() + 0.01,
        };
        let (x0, x1) = (4.0 * rng.next_f32(), 4.0 * rng.next_f32());
        let z = C::new(-0.5 * f64::from(x0 + x1), -0.5 * f64::from((x0 - x1).abs())).exp(); // exp(−(X̄ + iS))
        let u = z.scale(f64::from(r.u0)).add(C::new(f64::from(r.u1), 0.0));
        let v = z.scale(f64::from(r.v0)).add(C::new(f64::from(r.v1), 0.0));
        let want = u.div(v).re;
        let got = f64::from(r.jackknife(x0, x1));
        assert!(
            (got - want).abs() <= 1e-5 * want.abs().max(1.0),
            "{r:?} X=({x0},{x1}): {got} vs {want}"
        );
    }
}

#[test]
fn weights_of_both_strategies_sum_to_one() {
    let mut rng = Pcg::new(10);
    for _ in 0..10_000 {
        let (mu, p0) = (5.0 * rng.next_f32() + 1e-3, 5.0 * rng.next_f32() + 1e-3);
        let (x0, x1) = (3.0 * rng.next_f32(), 3.0 * rng.next_f32());
        let jack =
            Ratio::free_flight(mu, p0).jackknife(x0, x1) + Ratio::other(mu, p0).jackknife(x0, x1);
        let naive = Ratio::free_flight(mu, p0).naive(x0) + Ratio::other(mu, p0).naive(x0);
        assert!((jack - 1.0).abs() < 1e-5 && (naive - 1.0).abs() < 1e-5, "sums {jack} {naive}");
        let m = miller_weight(mu, p0, rng.next_f32());
        assert!((0.0..=1.0).contains(&m));
    }
}

#[test]
fn fig7_jackknife_weight_has_less_bias_than_naive() {
    let r = Ratio { u0: 1.0, u1: 0.0, v0: 1.0, v1: 0.5 };
    // (τ, σ) below the dashed line σ = 1.645τ, away from the pole's real part ln(v0/v1) = 0.69.
    for (i, (tau, sigma)) in [(2.0f64, 1.0f64), (1.5, 0.8), (3.0, 1.5)].into_iter().enumerate() {
        let exact = f64::from(r.naive(tau as f32));
        let mut rng = Pcg::new(20 + i as u32);
        let (mut jack, mut naive) = (Moments::default(), Moments::default());
        for _ in 0..1_000_000 {
            let x0 = (tau + sigma * normal(&mut rng)) as f32;
            let x1 = (tau + sigma * normal(&mut rng)) as f32;
            jack.add(f64::from(r.jackknife(x0, x1)));
            naive.add(f64::from(r.naive(0.5 * (x0 + x1))));
        }
        let (bj, bn) = (jack.mean() - exact, naive.mean() - exact);
        println!(
            "τ={tau} σ={sigma}: bias jackknife {bj:.5} ± {:.5}, naive {bn:.5} ± {:.5}",
            jack.se(),
            naive.se()
        );
        assert!(
            bj.abs() + 4.5 * jack.se() < bn.abs() - 4.5 * naive.se(),
            "τ={tau} σ={sigma}: jackknife {bj} naive {bn}"
        );
    }
}
