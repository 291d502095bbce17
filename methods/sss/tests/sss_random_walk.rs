//! The random-walk subsurface reference (support::random_walk) against its analytic limits:
//! Gauss-Legendre quadrature, Chandrasekhar's H-function (its zeroth moment), the singly scattered fraction α(1 − ln 2)/2 of a normal beam, the whole
//! reflectance 1 − H(1)√(1 − α) of the half-space, and its mean over the cosines of a point
//! light, over 3 seeds each.

mod support;

use support::random_walk::{
    Medium, gauss_legendre_unit, h_function, plane_albedo, point_light, point_light_burley,
    searchlight,
};

#[test]
fn quadrature_and_h_function() {
    let (x, w) = gauss_legendre_unit(64);
    // Exact for polynomials of degree < 128: ∫_0^1 x^k = 1/(k+1).
    for k in [0, 1, 7, 40, 100] {
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
        assert!((q - 1.0 / (k + 1) as f64).abs() < 1e-13, "degree {k}: {q}");
    }
    for alpha in [0.3, 0.9, 0.99, 0.999] {
        // The zeroth moment: ∫_0^1 H = 2(1 − √(1 − α))/α.
        let moment: f64 = x.iter().zip(&w).map(|(x, w)| w * h_function(alpha, *x)).sum();
        let want = 2.0 * (1.0 - (1.0f64 - alpha).sqrt()) / alpha;
        assert!((moment - want).abs() < 2e-4, "α {alpha}: ∫H = {moment}, expected {want}");
    }
}

/// |got − want| within 4 standard errors (and a 3-seed check, every seed).
fn within(what: &str, (got, se): (f64, f64), want: f64) {
    assert!((got - want).abs() <= 4.0 * se, "{what}: {got} ± {se}, expected {want}");
}

#[test]
fn walk_meets_the_single_scattering_and_plane_albedo_limits() {
    for seed in 1..=3 {
        for alpha in [0.3, 0.9, 0.99] {
            let t = searchlight(&Medium::unit(alpha), 40_000, seed, 0.1, 10);
            within(
                &format!("α {alpha} seed {seed}: single scattering"),
                t.single_scattering(),
                alpha * (1.0 - 2f64.ln()) / 2.0,
            );
            within(
                &format!("α {alpha} seed {seed}: plane albedo"),
                t.reflectance(),
                plane_albedo(alpha, 1.0),
            );
        }
    }
}

#[test]
fn point_light_walk_meets_the_spherical_albedo() {
    // An isotropic point light's photons meet the plane with cosines uniform in (0, 1], so the
    // reflected fraction is ∫_0^1 (1 − H(μ)√(1 − α)) dμ = 1 − 2√(1 − α)(1 − √(1 − α))/α.
    for seed in 1..=3 {
        for alpha in [0.5, 0.95] {
            let t = point_light(&Medium::unit(alpha), 2.0, 40_000, seed, 0.5, 20);
            let s = (1.0f64 - alpha).sqrt();
            within(
                &format!("α {alpha} seed {seed}: point light"),
                t.reflectance(),
                1.0 - 2.0 * s * (1.0 - s) / alpha,
            );
        }
    }
    // The model's tally: weight A per photon, so its reflectance is A exactly.
    let m = point_light_burley(0.7, 0.5, 2.0, 1000, 1, 0.5, 20);
    assert!((m.reflectance().0 - 0.7).abs() < 1e-12 && m.reflectance().1 < 1e-9);
}
