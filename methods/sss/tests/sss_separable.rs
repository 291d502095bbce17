//! The separable baseline (sss::separable): its pre-integrated kernel against the
//! projection of Burley's radial density computed another way, its weights, the exactness of
//! the rank-1 kernel for an irradiance that varies along x only (eqs. 2.61-2.64) and its known
//! anisotropy on a diagonal edge, and the WGSL passes against the CPU twin.

use render::gpu::Gpu;
use sss::gpu::SssPass;
use sss::profile::radial_pdf;
use sss::screen_pass::step;
use sss::separable::{MAX_TAPS, kernel, kernel_cdf, one_sided_tail, tap_offsets};
use sss::{SssFrame, SssPassSettings, SssVariant};

/// P(X > a) for X = r cos φ, r from Burley's radial density, φ uniform: the mass beyond a of
/// the profile's projection, as ½ ∫_a^∞ p(r) (1 − (2/π) asin(a/r)) dr. Substituting
/// r = a + s² takes the square-root edge at r = a out; Simpson in s.
fn projected_tail(a: f64, d: f64) -> f64 {
    let (s_max, n) = ((80.0 * d).sqrt(), 200_000);
    let h = s_max / n as f64;
    let f = |s: f64| {
        let r = a + s * s;
        let angular =
            if r <= 0.0 { 0.0 } else { 1.0 - 2.0 / std::f64::consts::PI * (a / r).min(1.0).asin() };
        radial_pdf(r, d) * angular * 2.0 * s
    };
    let mut sum = f(0.0) + f(s_max);
    for i in 1..n {
        sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    0.5 * sum * h / 3.0
}

#[test]
fn kernel_is_the_projection_of_burleys_profile() {
    for d in [0.5, 1.0, 3.0] {
        assert!((one_sided_tail(0.0, d) - 0.5).abs() < 1e-12, "d {d}: {}", one_sided_tail(0.0, d));
        for a in [0.05, 0.3, 1.0, 2.5, 6.0, 15.0] {
            let (x, y) = (one_sided_tail(a * d, d), projected_tail(a * d, d));
            assert!((x - y).abs() < 2e-6, "d {d} a {a}: K0 form {x}, projection {y}");
        }
    }
    // The cdf is symmetric and monotone.
    for x in [0.1, 0.7, 4.0] {
        assert!((kernel_cdf(x, 1.0) + kernel_cdf(-x, 1.0) - 1.0).abs() < 1e-12);
        assert!(kernel_cdf(x, 1.0) < kernel_cdf(x * 1.1, 1.0));
    }
}

#[test]
fn weights_sum_to_one_and_are_symmetric() {
    for taps in [3, 17, 25, MAX_TAPS] {
        let k = kernel(taps, [4.0, 2.0, 1.0]).unwrap();
        assert_eq!(k.len(), taps as usize);
        let o = tap_offsets(taps);
        assert_eq!(o[taps as usize / 2], 0.0);
        for c in 1..4 {
            let sum: f32 = k.iter().map(|t| t[c]).sum();
            assert!((sum - 1.0).abs() < 1e-5, "taps {taps} channel {c}: {sum}");
            for i in 0..k.len() {
                assert!((k[i][c] - k[k.len() - 1 - i][c]).abs() < 1e-7 && k[i][c] >= 0.0);
                assert!((k[i][0] + k[k.len() - 1 - i][0]).abs() < 1e-6);
            }
        }
        // The narrower channels keep more mass in the centre tap.
        let centre = k[taps as usize / 2];
        assert!(centre[1] < centre[2] && centre[2] < centre[3], "{centre:?}");
    }
    assert!(kernel(4, [1.0; 3]).unwrap_err().contains("odd"));
    assert!(kernel(MAX_TAPS + 2, [1.0; 3]).is_err());
    assert!(kernel(5, [1.0, 0.0, 1.0]).unwrap_err().contains("positive"));
}

const HI: f64 = 1.0;
const LO: f64 = 0.15;
/// The edge's width in pixels: smooth, so the linear fetch's error stays small.
const EDGE: f64 = 1.5;

/// The irradiance across the edge at signed distance s (pixels): a logistic step.
fn b(s: f64) -> f64 {
    LO + (HI - LO) / (1.0 + (s / EDGE).exp())
}

/// max |b''|: (HI − LO) max|σ''| / EDGE², max|σ''| = 1/(6√3) for the logistic σ.
fn b_curvature() -> f64 {
    (HI - LO) / (6.0 * 3f64.sqrt()) / (EDGE * EDGE)
}

/// An edge along the line n·p = c (n unit), everything an SSS pixel (w = 1).
fn edge_frame(width: u32, height: u32, n: [f64; 2], c: f64, d_px: [f32; 3]) -> SssFrame {
    let irradiance = (0..width * height)
        .map(|i| {
            let p = [(i % width) as f64 + 0.5, (i / width) as f64 + 0.5];
            let v = b(n[0] * p[0] + n[1] * p[1] - c) as f32;
            [v, v, v, 1.0]
        })
        .collect();
    SssFrame { width, height, irradiance, d_px, focal_px: 0.0, motion: Vec::new() }
}

/// E[b(s − T)] for T from the kernel of shape d (pixels): the exact scattering of the edge by
/// the radially symmetric profile, whose projection on every direction is the kernel. Midpoint
/// rule on 4000 cells over ±40d, the cells' masses from the cdf, the tails at b's limits.
struct Exact {
    cells: Vec<(f64, f64)>,
    tail: f64,
}

impl Exact {
    fn new(d: f64) -> Self {
        let (n, t_max) = (4000, 40.0 * d);
        let h = 2.0 * t_max / n as f64;
        let cdf: Vec<f64> = (0..=n).map(|j| kernel_cdf(-t_max + j as f64 * h, d)).collect();
        Self {
            cells: (0..n).map(|j| (-t_max + (j as f64 + 0.5) * h, cdf[j + 1] - cdf[j])).collect(),
            tail: cdf[0],
        }
    }

    fn at(&self, s: f64) -> f64 {
        self.cells.iter().map(|(t, m)| m * b(s - t)).sum::<f64>() + self.tail * (HI + LO)
    }
}

#[test]
fn rank_one_kernel_is_exact_for_a_vertical_edge_not_a_diagonal_one() {
    let d_px = [3.0f32, 1.5, 0.75];
    let taps = MAX_TAPS;
    let k = kernel(taps, d_px).unwrap();
    let exact: Vec<Exact> = d_px.iter().map(|&d| Exact::new(d as f64)).collect();
    let offsets: Vec<f64> = k.iter().map(|t| t[0] as f64 * 3.0).collect();
    let size = 2 * (8.0 * 3.0f32).ceil() as u32 + 24;
    let margin = 8 * 3 + 1;
    let run = |n: [f64; 2], c: f64| -> (Vec<f64>, Vec<f64>) {
        let frame = edge_frame(size, size, n, c, d_px);
        let (results, _) = step(
            &frame,
            &SssPassSettings { variant: SssVariant::Separable { taps }, ..Default::default() },
            0,
            &[],
        );
        let (mut errors, mut bounds) = (vec![], vec![]);
        for y in margin..size - margin {
            for x in margin..size - margin {
                let r = results[(y * size + x) as usize];
                assert_eq!(r.count, 2 * taps);
                let s = n[0] * (x as f64 + 0.5) + n[1] * (y as f64 + 0.5) - c;
                for ch in 0..3 {
                    errors.push((r.rgb[ch] as f64 - exact[ch].at(s)).abs());
                    // For an edge along y the pass is one 1-D sum: it differs from the integral
                    // by at most Σ_i w_i × b's oscillation over tap i's cell, plus the linear
                    // fetch's error |b''|/8 and the f32 arithmetic.
                    let edge = |i: usize| {
                        if i == 0 {
                            f64::NEG_INFINITY
                        } else if i == offsets.len() {
                            f64::INFINITY
                        } else {
                            0.5 * (offsets[i - 1] + offsets[i])
                        }
                    };
                    let cells: f64 = (0..offsets.len())
                        .map(|i| k[i][ch + 1] as f64 * (b(s - edge(i)) - b(s - edge(i + 1))).abs())
                        .sum();
                    bounds.push(cells + b_curvature() / 8.0 + 1e-5);
                }
            }
        }
        (errors, bounds)
    };
    let half = size as f64 / 2.0;
    let (e_vertical, bound) = run([1.0, 0.0], half);
    for (e, b) in e_vertical.iter().zip(&bound) {
        assert!(e <= b, "vertical edge: error {e} over the discretisation bound {b}");
    }
    let (e_diagonal, _) =
        run([std::f64::consts::FRAC_1_SQRT_2; 2], half * std::f64::consts::SQRT_2);
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "separable vs exact: vertical edge max {:.5} (bound max {:.5}), diagonal edge max {:.5}",
        max(&e_vertical),
        max(&bound),
        max(&e_diagonal)
    );
    // k(x)k(y) is not radially symmetric: along the diagonal it scatters differently (the
    // separable filter's anisotropy).
    assert!(
        max(&e_diagonal) > 2.0 * max(&e_vertical),
        "diagonal {} vertical {}",
        max(&e_diagonal),
        max(&e_vertical)
    );
}

#[test]
fn gpu_separable_matches_the_cpu_twin() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let (w, h) = (23, 14);
    // Edges, falloff, varying w (as depth would), and a non-SSS block.
    let irradiance = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let lit = if x + 0.5 * y < 12.0 { 1.0 } else { 0.15 };
            let fall = 1.0 - 0.03 * y;
            let scale = if x >= 18.0 && y < 5.0 { 0.0 } else { 0.8 + 0.03 * x };
            [lit * fall, 0.8 * lit * fall, 0.6 * lit, scale]
        })
        .collect();
    let frame = SssFrame {
        width: w,
        height: h,
        irradiance,
        d_px: [1.5, 0.8, 0.4],
        focal_px: 0.0,
        motion: Vec::new(),
    };
    let mut pass = SssPass::new(&gpu, w, h).unwrap();
    for taps in [5, 25] {
        let settings =
            SssPassSettings { variant: SssVariant::Separable { taps }, ..Default::default() };
        pass.dispatch(&gpu, &frame, &settings, 0).unwrap();
        let gpu_results = pass.results(&gpu).unwrap();
        let (cpu_results, _) = step(&frame, &settings, 0, &[]);
        let mut differs_from_input = 0;
        for (i, (g, c)) in gpu_results.iter().zip(&cpu_results).enumerate() {
            assert_eq!(g.count, c.count, "taps {taps} pixel {i}");
            for ch in 0..3 {
                assert!(
                    (g.rgb[ch] - c.rgb[ch]).abs()
                        <= 1e-4 * g.rgb[ch].abs().max(c.rgb[ch].abs()) + 1e-6,
                    "taps {taps} pixel {i}: gpu {:?} cpu {:?}",
                    g.rgb,
                    c.rgb
                );
            }
            if (c.rgb[0] - frame.irradiance[i][0]).abs() > 1e-3 {
                differs_from_input += 1;
            }
        }
        assert!(
            differs_from_input > 20,
            "taps {taps}: the pass changed only {differs_from_input} pixels"
        );
    }
    assert!(
        pass.dispatch(
            &gpu,
            &frame,
            &SssPassSettings { variant: SssVariant::Separable { taps: 4 }, ..Default::default() },
            0
        )
        .unwrap_err()
        .to_string()
        .contains("odd")
    );
}
