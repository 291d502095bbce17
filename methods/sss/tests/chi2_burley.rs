//! Chi-square goodness-of-fit tests (testkit::chi2) of the SSS pass's radius sampling: the
//! analytic inverse of Burley's radial cdf (eqs. 5.4/5.5) in WGSL (sampling.wgsl, drawn and its
//! pdf evaluated by tests/chi2/burley_kernel.wgsl) and in its CPU twin (sss::sampling), each
//! against the radial density (e^{-r/d} + e^{-r/(3d)}) / (4d) that weighs the samples.
//!
//! The radius has an unbounded tail, so it is binned in x = r / (r + d) ∈ [0, 1) with the pdf
//! carried over by the Jacobian dr/dx = d / (1 − x)². The fast inverse g(ξ) of eq. 5.6 is the
//! thesis's approximation of this inverse (its density is not the pdf the pass divides by), so it
//! is not tested against it. Mitsuba 3 has no Burley profile: the profile's own closed forms
//! (the cdf, its integral) are the reference, and the subsurface ground truth's random walk is
//! checked against its closed forms in tests/sss_random_walk.rs.
//!
//! Sizes: 2^20 draws per configuration, 64 bins; d = 0.5 and 3 on each side.

use render::pass_library::PassLibrary;
use render::shader::Module;
use testkit::chi2::{self, IntervalBins, Kernel};
use testkit::test_scenes::gpu;

const DRAWS: u32 = 1 << 20;
const SHAPES: [f32; 2] = [0.5, 3.0];
const BINS: IntervalBins = IntervalBins { lo: 0.0, hi: 1.0, bins: 64 };

fn to_x(r: f64, d: f64) -> f64 {
    r / (r + d)
}

fn to_r(x: f64, d: f64) -> f64 {
    d * x / (1.0 - x)
}

/// The density of x from that of r at the radii `to_r(x)`.
fn density_of_x(pdf_r: &[f64], xs: &[f64], d: f64) -> Vec<f64> {
    pdf_r.iter().zip(xs).map(|(p, &x)| p * d / ((1.0 - x) * (1.0 - x))).collect()
}

fn kernel() -> Kernel {
    let source = Module {
        path: "package::sss::chi2_burley_kernel".into(),
        file: "methods/sss/tests/chi2/burley_kernel.wgsl".into(),
        source: include_str!("chi2/burley_kernel.wgsl").into(),
    };
    Kernel::new(
        gpu(),
        "package::sss::chi2_bindings",
        vec![PassLibrary::module("package::pt_sampling"), render::wgsl_file!("sampling.wgsl")],
        source,
        ["radius_sample_main", "radius_pdf_main"],
    )
    .expect("the Burley test kernel compiles")
}

#[test]
fn wgsl_burley_radius_sampling_fits_the_radial_pdf() {
    let k = kernel();
    for (seed, &d) in SHAPES.iter().enumerate() {
        let dd = d as f64;
        let params =
            [[d, 0.0, 0.0, 0.0], [chi2::bits(DRAWS), chi2::bits(seed as u32 + 1), 0.0, 0.0]];
        let drawn = k.run(gpu(), 0, &params, &[], DRAWS);
        let observed = BINS.histogram(drawn.iter().map(|r| {
            let r = r[0] as f64;
            (to_x(r, dd), r.is_finite() && r >= 0.0)
        }));
        let integral = BINS.integrate(&observed, &mut |xs| {
            let points: Vec<[f32; 4]> =
                xs.iter().map(|&x| [to_r(x, dd) as f32, 0.0, 0.0, 0.0]).collect();
            let mut params = params;
            params[1][0] = chi2::bits(points.len() as u32);
            let pdf: Vec<f64> = k
                .run(gpu(), 1, &params, &points, points.len() as u32)
                .iter()
                .map(|r| r[0] as f64)
                .collect();
            density_of_x(&pdf, xs, dd)
        });
        let what = format!("WGSL Burley radius, d {d}");
        let o = chi2::assert_fits(&what, &observed, &integral, DRAWS as u64);
        eprintln!(
            "{what}: chi2 {:.1} dof {} p {:.3} integral {:.6}",
            o.statistic, o.dof, o.p_value, o.integral
        );
    }
}

#[test]
fn cpu_burley_radius_sampling_fits_the_radial_pdf() {
    for (seed, &d) in SHAPES.iter().enumerate() {
        let dd = d as f64;
        let mut rng = render::scene::SplitMix64::new(40 + seed as u64);
        let observed = BINS.histogram((0..DRAWS).map(|_| {
            let r = sss::sampling::sample_radius(rng.next_f32(), d, false) as f64;
            (to_x(r, dd), r.is_finite() && r >= 0.0)
        }));
        let integral = BINS.integrate(&observed, &mut |xs| {
            let pdf: Vec<f64> = xs
                .iter()
                .map(|&x| sss::sampling::radial_pdf(to_r(x, dd) as f32, d) as f64)
                .collect();
            density_of_x(&pdf, xs, dd)
        });
        let what = format!("CPU Burley radius, d {d}");
        let o = chi2::assert_fits(&what, &observed, &integral, DRAWS as u64);
        eprintln!(
            "{what}: chi2 {:.1} dof {} p {:.3} integral {:.6}",
            o.statistic, o.dof, o.p_value, o.integral
        );
    }
}
