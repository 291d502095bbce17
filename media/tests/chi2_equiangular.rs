//! Chi-square goodness-of-fit tests (testkit::chi2) of equiangular sampling (Kulla and Fajardo
//! 2012), the volume path tracer's distance sampler towards a point light: the WGSL of
//! media_mis.wgsl (drawn and its pdf evaluated by a test kernel, tests/chi2/equiangular_kernel.wgsl)
//! and its CPU twin (media::equiangular), each against its own pdf over the sampled interval.
//! The volume path tracer's other sampler, the isotropic phase function, draws with the path
//! tracer's `sample_uniform_sphere` against 1/4π: render/tests/chi2_sampling.rs tests it.
//!
//! Sizes: 2^20 draws per configuration, 64 bins over [a, b]; three configurations (a light
//! close to the ray, far from it, its foot point before the interval) on each side.

use media::equiangular::Equiangular;
use render::pass_library::PassLibrary;
use render::shader::Module;
use testkit::chi2::{self, IntervalBins, Kernel};
use testkit::test_scenes::gpu;

const DRAWS: u32 = 1 << 20;

/// (Δ, D, a, b): the light's foot point on the ray and its distance from it, the interval.
const CONFIGURATIONS: [(f32, f32, f32, f32); 3] =
    [(1.0, 0.1, 0.0, 3.0), (2.0, 1.5, 0.5, 6.0), (-0.5, 0.4, 0.0, 2.0)];

fn kernel() -> Kernel {
    let source = Module {
        path: "package::media::chi2_equiangular_kernel".into(),
        file: "media/tests/chi2/equiangular_kernel.wgsl".into(),
        source: include_str!("chi2/equiangular_kernel.wgsl").into(),
    };
    Kernel::new(
        gpu(),
        "package::media::chi2_bindings",
        vec![PassLibrary::module("package::pt_sampling"), render::wgsl_file!("media_mis.wgsl")],
        source,
        ["equiangular_sample_main", "equiangular_pdf_main"],
    )
    .expect("the equiangular test kernel compiles")
}

#[test]
fn wgsl_equiangular_sampling_fits_its_pdf() {
    let k = kernel();
    for (seed, &(delta, d, a, b)) in CONFIGURATIONS.iter().enumerate() {
        let params = [[delta, d, a, b], [chi2::bits(DRAWS), chi2::bits(seed as u32 + 1), 0.0, 0.0]];
        let drawn = k.run(gpu(), 0, &params, &[], DRAWS);
        let bins = IntervalBins { lo: a as f64, hi: b as f64, bins: 64 };
        // f32 rounding may put a draw a hair outside [a, b]: it belongs to the end bin.
        let observed =
            bins.histogram(drawn.iter().map(|r| ((r[0] as f64).clamp(bins.lo, bins.hi), true)));
        let integral = bins.integrate(&observed, &mut |t| {
            let points: Vec<[f32; 4]> = t.iter().map(|&t| [t as f32, 0.0, 0.0, 0.0]).collect();
            let mut params = params;
            params[1][0] = chi2::bits(points.len() as u32);
            k.run(gpu(), 1, &params, &points, points.len() as u32)
                .iter()
                .map(|r| r[0] as f64)
                .collect()
        });
        let what = format!("WGSL equiangular, Δ {delta}, D {d}, [{a}, {b}]");
        let o = chi2::assert_fits(&what, &observed, &integral, DRAWS as u64);
        eprintln!(
            "{what}: chi2 {:.1} dof {} p {:.3} integral {:.6}",
            o.statistic, o.dof, o.p_value, o.integral
        );
    }
}

#[test]
fn cpu_equiangular_sampling_fits_its_pdf() {
    for (seed, &(delta, d, a, b)) in CONFIGURATIONS.iter().enumerate() {
        let e = Equiangular::from_foot(delta, d, a, b);
        let mut rng = media::Pcg::new(100 + seed as u32);
        let bins = IntervalBins { lo: a as f64, hi: b as f64, bins: 64 };
        let observed = bins.histogram(
            (0..DRAWS).map(|_| ((e.sample(rng.next_f32()) as f64).clamp(bins.lo, bins.hi), true)),
        );
        let integral =
            bins.integrate(&observed, &mut |t| t.iter().map(|&t| e.pdf(t as f32) as f64).collect());
        let what = format!("CPU equiangular, Δ {delta}, D {d}, [{a}, {b}]");
        let o = chi2::assert_fits(&what, &observed, &integral, DRAWS as u64);
        eprintln!(
            "{what}: chi2 {:.1} dof {} p {:.3} integral {:.6}",
            o.statistic, o.dof, o.p_value, o.integral
        );
    }
}
