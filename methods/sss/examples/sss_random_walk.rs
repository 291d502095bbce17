//! The diffusion model's own bias (support::random_walk): a random walk in a half-space of
//! unit mean free path and albedo α against Burley's profile with the walk's own A (its
//! normal-incidence reflectance) and d = ℓ_d / s(A) (Θ3, eq. 2.44, ℓ_d = 1/σ_tr). Per α: A
//! from the walk and from the H-function; under a searchlight the radii holding 50% and 90% of
//! the exitance (walk, Burley) and the largest gap between the two radial cdfs; under a point
//! light at height ℓ_d the walk's and the model's reflected fractions and the relative L1 gap
//! between their radial exitance.
//!
//! cargo run --release -p render --example sss_random_walk -- [PATHS]

#[path = "../tests/support/mod.rs"]
mod support;

use sss::inverse::numeric_inverse;
use sss::profile::{cdf, scaling_from_dmfp};
use support::random_walk::{Medium, plane_albedo, point_light, point_light_burley, searchlight};

fn main() {
    let paths: u64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("PATHS: a whole number"))
        .unwrap_or(400_000);
    println!("{paths} walks per row, seed 1 (model tally: seed 2)\n");
    println!(
        "| α | A walk | A = 1 − H(1)√(1−α) | ℓ_d | d | r50 walk / Burley | r90 walk / Burley | max cdf gap | point light: R walk / model | exitance L1 gap |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for alpha in [0.9, 0.99, 0.999] {
        let medium = Medium::unit(alpha);
        let ld = medium.diffuse_mean_free_path();
        let width = ld / 50.0;
        let walk = searchlight(&medium, paths, 1, width, 2000);
        let (a, se) = walk.reflectance();
        let d = ld / scaling_from_dmfp(a);
        let radius = |f: &dyn Fn(f64) -> f64, q: f64| {
            let (mut lo, mut hi) = (0.0, 40.0 * ld);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if f(mid) < q { lo = mid } else { hi = mid }
            }
            lo
        };
        let walk_cdf = |r: f64| walk.cdf(r);
        let gap = (1..2000)
            .map(|k| (walk.cdf(k as f64 * width) - cdf(k as f64 * width, d)).abs())
            .fold(0.0, f64::max);
        let h = ld;
        let lit = point_light(&medium, h, paths, 1, width * 4.0, 500);
        let model = point_light_burley(a, d, h, paths, 2, width * 4.0, 500);
        let l1: f64 = lit.bins.iter().zip(&model.bins).map(|(x, y)| (x - y).abs()).sum::<f64>()
            / lit.bins.iter().sum::<f64>();
        println!(
            "| {alpha} | {a:.4} ± {se:.4} | {:.4} | {ld:.3} | {d:.4} | {:.3} / {:.3} | {:.3} / {:.3} | {gap:.3} | {:.4} / {:.4} | {l1:.3} |",
            plane_albedo(alpha, 1.0),
            radius(&walk_cdf, 0.5),
            numeric_inverse(0.5, d),
            radius(&walk_cdf, 0.9),
            numeric_inverse(0.9, d),
            lit.reflectance().0,
            model.reflectance().0,
        );
    }
}
