//! Chi-square goodness-of-fit tests of sampling routines, as Mitsuba 3's `ChiSquareTest`
//! (after Wenzel Jakob's tests in Mitsuba 0.5): draw many samples, histogram them over a domain
//! (the sphere in θ/φ bins or in bins around a narrow lobe's axis, or an interval), integrate
//! the routine's own pdf over every bin, pool the bins whose expected count is below 5, and
//! reject when Pearson's statistic has a p-value below the significance, Šidák-corrected over
//! the whole set of such tests in the workspace ([`TESTS_IN_SET`]). Also reported: the pdf's integral over the domain, which must
//! equal the fraction of draws the routine returned as valid.
//!
//! Used by the sampling tests of `render`, `media` and `methods/sss` (their `tests/chi2_*.rs`);
//! the pdf is evaluated by the caller (on the GPU for WGSL routines) at the points this module
//! asks for, so a wrong pdf in the renderer's own code fails the test.

use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

use render::compute::{self, BufferBinding};
use render::error::RenderError;
use render::gpu::Gpu;
use render::shader::{Module, Program};

/// The probability that a correct set of samplers fails any test of the set.
pub const SIGNIFICANCE: f64 = 0.01;

/// Chi-square tests in the workspace's set (render/tests/chi2_sampling.rs: 23,
/// media/tests/chi2_equiangular.rs: 6, media/tests/chi2_free_flight.rs: 6,
/// methods/sss/tests/chi2_burley.rs: 4): each rejects at the Šidák level
/// 1 − (1 − [`SIGNIFICANCE`])^(1/n).
pub const TESTS_IN_SET: u32 = 39;

/// The per-test rejection level: 1 − (1 − α)^(1/n).
pub fn per_test_level() -> f64 {
    1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / TESTS_IN_SET as f64)
}

/// Bins below this expected count are pooled (the χ² approximation's usual rule).
pub const MIN_EXPECTED: f64 = 5.0;

/// Gauss-Legendre nodes and weights on [-1, 1], 5 points (exact to degree 9).
const GAUSS5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// A bin whose 5 x 5 Gauss values are not all within this ratio of each other (a pdf's edge, a
/// zero and a non-zero, a steep lobe) is integrated again on a fine midpoint grid.
const ROUGH_RATIO: f64 = 2.0;
/// The fine grid's points per axis: a straight edge through a bin is placed to 1/64 of its width.
/// A bin with draws that the fine grid sees no pdf in (a corner of a triangle light poking
/// between its points) is integrated once more at 4 times the resolution.
const FINE: usize = 64;

/// Bins over the unit sphere: `theta` equal steps of the polar angle θ ∈ [0, π] from +z and
/// `phi` equal steps of the azimuth φ ∈ [0, 2π) from +x. Even `theta` puts a bin edge at the
/// horizon, where a hemisphere's pdf jumps.
#[derive(Clone, Copy, Debug)]
pub struct SphereBins {
    pub theta: usize,
    pub phi: usize,
}

impl SphereBins {
    pub fn count(&self) -> usize {
        self.theta * self.phi
    }

    /// The bin of direction `d` (normalised here); `None` for a zero or non-finite one.
    pub fn index(&self, d: [f32; 3]) -> Option<usize> {
        let [x, y, z] = d.map(f64::from);
        let len = (x * x + y * y + z * z).sqrt();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let theta = (z / len).clamp(-1.0, 1.0).acos();
        let phi = y.atan2(x).rem_euclid(2.0 * PI);
        let i = ((theta / PI * self.theta as f64) as usize).min(self.theta - 1);
        let j = ((phi / (2.0 * PI) * self.phi as f64) as usize).min(self.phi - 1);
        Some(i * self.phi + j)
    }

    /// Counts of `dirs` per bin; a direction with `valid` false is not counted.
    pub fn histogram(&self, samples: impl IntoIterator<Item = ([f32; 3], bool)>) -> Vec<f64> {
        direction_histogram(self.count(), |d| self.index(d), samples)
    }

    fn direction(theta: f64, phi: f64) -> [f32; 3] {
        let s = theta.sin();
        [(s * phi.cos()) as f32, (s * phi.sin()) as f32, theta.cos() as f32]
    }

    /// Points and solid-angle weights (sin θ dθ dφ) covering `bin` on an n x n grid: Gauss or
    /// midpoint.
    fn points(&self, bin: usize, fine: usize) -> Vec<([f32; 3], f64)> {
        let (dt, dp) = (PI / self.theta as f64, 2.0 * PI / self.phi as f64);
        let (t0, p0) = ((bin / self.phi) as f64 * dt, (bin % self.phi) as f64 * dp);
        let axis = |n0: f64, step: f64| quadrature(n0, step, fine);
        let (ts, ps) = (axis(t0, dt), axis(p0, dp));
        let mut out = Vec::with_capacity(ts.len() * ps.len());
        for &(t, wt) in &ts {
            for &(p, wp) in &ps {
                out.push((Self::direction(t, p), wt * wp * t.sin()));
            }
        }
        out
    }

    /// The integral of the pdf over every bin. `pdf` evaluates the routine's pdf (solid angle)
    /// at a batch of unit directions (one GPU dispatch for all of them); `observed` (the
    /// histogram) marks bins to integrate finely where the coarse points see no pdf.
    pub fn integrate(
        &self,
        observed: &[f64],
        pdf: &mut dyn FnMut(&[[f32; 3]]) -> Vec<f64>,
    ) -> Vec<f64> {
        integrate_bins(
            self.count(),
            &|b| grid_neighbours(self.theta, self.phi, b),
            observed,
            &mut |bin, fine| self.points(bin, fine),
            pdf,
        )
    }
}

/// The 8 neighbours of bin `b` of a θ x φ grid (φ wraps around, θ does not).
fn grid_neighbours(theta: usize, phi: usize, b: usize) -> Vec<usize> {
    let (nt, np) = (theta as i64, phi as i64);
    let (i, j) = ((b / phi) as i64, (b % phi) as i64);
    let mut out = Vec::with_capacity(8);
    for di in -1..=1 {
        for dj in -1..=1 {
            let (a, c) = (i + di, (j + dj).rem_euclid(np));
            if (di, dj) != (0, 0) && (0..nt).contains(&a) {
                out.push((a * np + c) as usize);
            }
        }
    }
    out
}

/// Bins over the unit sphere around a lobe's axis: the angle θ' from `axis` warped so that
/// tan(θ'/2) = `scale` tan(π x / 2), x in `theta` equal steps of [0, 1] (θ' from 0 to π), and
/// the azimuth about the axis in `phi` equal steps. A lobe of width about `scale` in tan(θ'/2)
/// (GGX of α = `scale` around the mirror direction: θ' ≈ 2 θ_h) spreads over all the x steps
/// (its mass in x is about (π/2) sin(π x) at normal view), where [`SphereBins`] would put it
/// inside a few bins at low roughness.
#[derive(Clone, Copy, Debug)]
pub struct LobeBins {
    /// Unit axis of the lobe.
    pub axis: [f64; 3],
    pub scale: f64,
    pub theta: usize,
    pub phi: usize,
}

impl LobeBins {
    pub fn count(&self) -> usize {
        self.theta * self.phi
    }

    /// An orthonormal frame (tangent, bitangent, axis).
    fn frame(&self) -> [[f64; 3]; 3] {
        let a = self.axis;
        let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let a = a.map(|x| x / len);
        // Any vector not parallel to the axis, made orthogonal to it.
        let h = if a[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let d = h[0] * a[0] + h[1] * a[1] + h[2] * a[2];
        let t = [h[0] - d * a[0], h[1] - d * a[1], h[2] - d * a[2]];
        let tl = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        let t = t.map(|x| x / tl);
        let b = [a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0]];
        [t, b, a]
    }

    /// The bin of direction `d`; `None` for a zero or non-finite one.
    pub fn index(&self, d: [f32; 3]) -> Option<usize> {
        let d = d.map(f64::from);
        let [t, b, a] = self.frame();
        let dot = |u: [f64; 3]| u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
        let (x, y, z) = (dot(t), dot(b), dot(a));
        let len = (x * x + y * y + z * z).sqrt();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        // tan(θ'/2) = sin θ' / (1 + cos θ'), without acos's loss of precision near the axis.
        let rho = (x * x + y * y).sqrt();
        let half_tan = rho / (len + z);
        let u = (half_tan / self.scale).atan() * 2.0 / PI;
        let phi = y.atan2(x).rem_euclid(2.0 * PI);
        let i = ((u * self.theta as f64) as usize).min(self.theta - 1);
        let j = ((phi / (2.0 * PI) * self.phi as f64) as usize).min(self.phi - 1);
        Some(i * self.phi + j)
    }

    /// Counts per bin of the valid directions.
    pub fn histogram(&self, samples: impl IntoIterator<Item = ([f32; 3], bool)>) -> Vec<f64> {
        direction_histogram(self.count(), |d| self.index(d), samples)
    }

    /// Points and solid-angle weights (sin θ' dθ'/dx dx dφ) covering `bin` (as
    /// [`SphereBins`]'s).
    fn points(&self, bin: usize, fine: usize) -> Vec<([f32; 3], f64)> {
        let (dx, dp) = (1.0 / self.theta as f64, 2.0 * PI / self.phi as f64);
        let (x0, p0) = ((bin / self.phi) as f64 * dx, (bin % self.phi) as f64 * dp);
        let axis = |n0: f64, step: f64| quadrature(n0, step, fine);
        let [t, b, a] = self.frame();
        let s = self.scale;
        let mut out = Vec::new();
        for &(x, wx) in &axis(x0, dx) {
            let tx = (0.5 * PI * x).tan();
            let theta = 2.0 * (s * tx).atan();
            let dtheta = PI * s * (1.0 + tx * tx) / (1.0 + s * s * tx * tx);
            let (st, ct) = theta.sin_cos();
            for &(p, wp) in &axis(p0, dp) {
                let (sp, cp) = p.sin_cos();
                let (lx, ly) = (st * cp, st * sp);
                let d: [f32; 3] =
                    std::array::from_fn(|k| (lx * t[k] + ly * b[k] + ct * a[k]) as f32);
                out.push((d, wx * wp * dtheta * st));
            }
        }
        out
    }

    /// The integral of the pdf over every bin (as [`SphereBins::integrate`]).
    pub fn integrate(
        &self,
        observed: &[f64],
        pdf: &mut dyn FnMut(&[[f32; 3]]) -> Vec<f64>,
    ) -> Vec<f64> {
        integrate_bins(
            self.count(),
            &|b| grid_neighbours(self.theta, self.phi, b),
            observed,
            &mut |bin, fine| self.points(bin, fine),
            pdf,
        )
    }
}

/// Counts per bin (of `count`, as `index` places them) of the valid directions.
fn direction_histogram(
    count: usize,
    index: impl Fn([f32; 3]) -> Option<usize>,
    samples: impl IntoIterator<Item = ([f32; 3], bool)>,
) -> Vec<f64> {
    let mut h = vec![0.0; count];
    for (d, valid) in samples {
        if valid && let Some(i) = index(d) {
            h[i] += 1.0;
        }
    }
    h
}

/// Points and weights covering [n0, n0 + step]: `fine` midpoints, or Gauss-Legendre's five
/// nodes when `fine` is 0.
fn quadrature(n0: f64, step: f64, fine: usize) -> Vec<(f64, f64)> {
    if fine > 0 {
        (0..fine)
            .map(|k| (n0 + (k as f64 + 0.5) / fine as f64 * step, step / fine as f64))
            .collect()
    } else {
        GAUSS5.iter().map(|&(x, w)| (n0 + 0.5 * (x + 1.0) * step, 0.5 * w * step)).collect()
    }
}

/// Bins of equal width over [lo, hi].
#[derive(Clone, Copy, Debug)]
pub struct IntervalBins {
    pub lo: f64,
    pub hi: f64,
    pub bins: usize,
}

impl IntervalBins {
    pub fn index(&self, x: f64) -> Option<usize> {
        if !(x >= self.lo && x <= self.hi) {
            return None;
        }
        Some((((x - self.lo) / (self.hi - self.lo) * self.bins as f64) as usize).min(self.bins - 1))
    }

    /// Counts per bin of the valid samples; a sample outside [lo, hi] is an error (its pdf
    /// mass lies outside the tested domain).
    pub fn histogram(&self, samples: impl IntoIterator<Item = (f64, bool)>) -> Vec<f64> {
        let mut h = vec![0.0; self.bins];
        for (x, valid) in samples {
            if valid {
                let i = self.index(x).unwrap_or_else(|| {
                    panic!("sample {x} outside the tested interval [{}, {}]", self.lo, self.hi)
                });
                h[i] += 1.0;
            }
        }
        h
    }

    fn points(&self, bin: usize, fine: usize) -> Vec<(f64, f64)> {
        let w = (self.hi - self.lo) / self.bins as f64;
        let x0 = self.lo + bin as f64 * w;
        // As many points as a direction bin's fine grid has.
        quadrature(x0, w, fine * fine)
    }

    /// The integral of the pdf over every bin; `pdf` evaluates it at a batch of points
    /// (`observed` as [`SphereBins::integrate`]'s).
    pub fn integrate(&self, observed: &[f64], pdf: &mut dyn FnMut(&[f64]) -> Vec<f64>) -> Vec<f64> {
        let neighbours = |b: usize| -> Vec<usize> {
            [b.wrapping_sub(1), b + 1].into_iter().filter(|&n| n < self.bins).collect()
        };
        integrate_bins(
            self.bins,
            &neighbours,
            observed,
            &mut |bin, fine| self.points(bin, fine),
            pdf,
        )
    }
}

/// Gauss quadrature in every bin, then a fine midpoint grid in the bins where the pdf is rough.
fn integrate_bins<P: Copy>(
    bins: usize,
    neighbours: &dyn Fn(usize) -> Vec<usize>,
    observed: &[f64],
    points: &mut dyn FnMut(usize, usize) -> Vec<(P, f64)>,
    pdf: &mut dyn FnMut(&[P]) -> Vec<f64>,
) -> Vec<f64> {
    let coarse: Vec<Vec<(P, f64)>> = (0..bins).map(|b| points(b, 0)).collect();
    let values = pdf(&coarse.iter().flatten().map(|p| p.0).collect::<Vec<_>>());
    let per = coarse[0].len();
    let mut integral = vec![0.0; bins];
    let mut steep = vec![false; bins];
    let mut nonzero = vec![false; bins];
    for b in 0..bins {
        let v = &values[b * per..(b + 1) * per];
        let (lo, hi) = v.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        steep[b] = hi > 0.0 && hi > ROUGH_RATIO * lo;
        nonzero[b] = hi > 0.0;
        integral[b] = v.iter().zip(&coarse[b]).map(|(x, p)| x * p.1).sum();
    }
    // Also next to a bin of the other zero-ness, and where draws fell but no Gauss point saw the
    // pdf: an edge or a corner of the pdf's support may clip a bin between its Gauss points.
    let rough: Vec<usize> = (0..bins)
        .filter(|&b| {
            steep[b]
                || (!nonzero[b] && observed[b] > 0.0)
                || neighbours(b).iter().any(|&n| nonzero[n] != nonzero[b])
        })
        .collect();
    let mut refine = |bins: &[usize], n: usize, integral: &mut [f64]| {
        if bins.is_empty() {
            return;
        }
        let fine: Vec<Vec<(P, f64)>> = bins.iter().map(|&b| points(b, n)).collect();
        let values = pdf(&fine.iter().flatten().map(|p| p.0).collect::<Vec<_>>());
        let per = fine[0].len();
        for (k, &b) in bins.iter().enumerate() {
            integral[b] =
                values[k * per..(k + 1) * per].iter().zip(&fine[k]).map(|(x, p)| x * p.1).sum();
        }
    };
    refine(&rough, FINE, &mut integral);
    let unseen: Vec<usize> =
        (0..bins).filter(|&b| observed[b] > 0.0 && !(integral[b] > 0.0)).collect();
    refine(&unseen, 4 * FINE, &mut integral);
    integral
}

/// What a test found.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Pearson's statistic over the pooled cells, its degrees of freedom and p-value.
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// The pdf's integral over the domain, and the fraction of draws counted as valid.
    pub integral: f64,
    pub valid_fraction: f64,
    pub draws: u64,
}

impl Outcome {
    /// Whether the integral of the pdf agrees with the valid fraction: within 5 binomial
    /// standard errors of the fraction, plus [`INTEGRAL_ALLOWANCE`].
    pub fn integral_matches(&self) -> bool {
        let f = self.valid_fraction;
        let se = (f * (1.0 - f) / self.draws as f64).sqrt();
        (self.integral - f).abs() <= 5.0 * se + INTEGRAL_ALLOWANCE
    }
}

/// The quadrature's and an f32 pdf's error allowance on an integral of 1 (the tests measure the
/// integral of pdfs known to integrate to 1 exactly: cos/π, 1/4π, to better than 1e-5).
pub const INTEGRAL_ALLOWANCE: f64 = 2e-4;

/// Pearson's χ² of `observed` counts (valid draws per bin) against `draws` x `integral` (the
/// pdf's integral per bin), bins below [`MIN_EXPECTED`] pooled in order of expectation. Err: a
/// bin with draws where the pdf is zero.
pub fn test(observed: &[f64], integral: &[f64], draws: u64) -> Result<Outcome, String> {
    assert_eq!(observed.len(), integral.len());
    let n = draws as f64;
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| integral[a].total_cmp(&integral[b]));
    let (mut statistic, mut cells) = (0.0, 0usize);
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    for &i in &order {
        let e = integral[i] * n;
        let o = observed[i];
        if !(e > 0.0) {
            if o > 0.0 {
                return Err(format!("{o} samples in bin {i}, where the pdf integrates to {e}"));
            }
            continue;
        }
        if e < MIN_EXPECTED {
            pool_obs += o;
            pool_exp += e;
            if pool_exp >= MIN_EXPECTED {
                statistic += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
                cells += 1;
                (pool_obs, pool_exp) = (0.0, 0.0);
            }
        } else {
            statistic += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_exp > 0.0 {
        // The remainder joins the cells as one more (its expectation may be below 5).
        statistic += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        cells += 1;
    }
    if cells < 2 {
        return Err(format!("only {cells} cell(s) after pooling: too few samples or bins"));
    }
    let dof = cells - 1;
    let p_value = ChiSquared::new(dof as f64).expect("dof > 0").sf(statistic);
    let valid: f64 = observed.iter().sum();
    Ok(Outcome {
        statistic,
        dof,
        p_value,
        integral: integral.iter().sum(),
        valid_fraction: valid / n,
        draws,
    })
}

/// [`test`], then panics naming `what` unless the p-value is at least [`per_test_level`] and
/// the integral of the pdf matches the valid fraction.
pub fn assert_fits(what: &str, observed: &[f64], integral: &[f64], draws: u64) -> Outcome {
    let outcome = test(observed, integral, draws).unwrap_or_else(|e| panic!("{what}: {e}"));
    let level = per_test_level();
    assert!(
        outcome.p_value >= level,
        "{what}: chi-square {:.1} on {} degrees of freedom, p = {:.3e} < {level:.2e} \
         (pdf integral {:.5}, valid fraction {:.5}, {draws} draws)",
        outcome.statistic,
        outcome.dof,
        outcome.p_value,
        outcome.integral,
        outcome.valid_fraction
    );
    assert!(
        outcome.integral_matches(),
        "{what}: the pdf integrates to {:.6} but {:.6} of {draws} draws were valid",
        outcome.integral,
        outcome.valid_fraction
    );
    outcome
}

/// The environment variable that swaps a module of a test kernel's program for a file:
/// `MODULE=PATH[;MODULE=PATH...]`, e.g. `package::pt_bsdf=/tmp/broken_pt_bsdf.wgsl`. How a
/// break is shown without rebuilding: copy the module, break its pdf, run the test with it.
pub const REPLACE_VAR: &str = "FLICKER_CHI2_REPLACE";

/// `program` with the modules named in [`REPLACE_VAR`] read from their files (unchanged when
/// it is not set).
pub fn with_replacements(program: Program) -> Program {
    let Ok(spec) = std::env::var(REPLACE_VAR) else {
        return program;
    };
    let mut program = program;
    for item in spec.split(';').filter(|s| !s.is_empty()) {
        let (path, file) = item
            .split_once('=')
            .unwrap_or_else(|| panic!("{REPLACE_VAR}: expected MODULE=PATH, got {item:?}"));
        let source =
            std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{REPLACE_VAR}: {file}: {e}"));
        let module = Module {
            path: path.to_string().into(),
            file: file.to_string().into(),
            source: source.into(),
        };
        assert!(
            program.modules.iter().chain(&program.entry_files).any(|m| m.path == module.path),
            "{REPLACE_VAR}: the program has no module {path}"
        );
        program = program.replacing(&module);
        eprintln!("{REPLACE_VAR}: {path} read from {file}");
    }
    program
}

/// A test kernel without the scene: its modules, and one @group(0) of three buffers that it
/// imports from `BINDINGS_PATH`-like module of the caller's choice: `params` and `points`
/// (read, `array<vec4f>`) and `result` (read-write, `array<vec4f>`, one per invocation).
/// Invocation i is `id.x + id.y * ROW` (workgroups of 64, [`ROW_GROUPS`] per row).
pub struct Kernel {
    layout: wgpu::BindGroupLayout,
    pipelines: Vec<wgpu::ComputePipeline>,
}

/// The kernel's buffers, in binding order.
pub const KERNEL_BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("params", "array<vec4f>"),
    BufferBinding::read("points", "array<vec4f>"),
    BufferBinding::read_write("result", "array<vec4f>"),
];

/// Workgroups of 64 per row of a dispatch: a kernel's ROW is 64 times this.
pub const ROW_GROUPS: u32 = 32768;

impl Kernel {
    /// `modules` (what the kernel imports), its bindings as module `bindings_path`, and the
    /// kernel file with `entries`.
    pub fn new<const N: usize>(
        gpu: &Gpu,
        bindings_path: &str,
        modules: Vec<Module>,
        kernel: Module,
        entries: [&str; N],
    ) -> Result<Self, RenderError> {
        let bindings = compute::group_module(bindings_path, 0, &KERNEL_BINDINGS, &[]);
        let program = with_replacements(Program::new(modules).with([bindings]).entry(kernel));
        let layout = compute::binding_layout(gpu, "chi2 kernel", &KERNEL_BINDINGS);
        let pipelines = compute::pipelines(gpu, "chi2 kernel", &program, &[&layout], entries)?;
        Ok(Self { layout, pipelines: pipelines.to_vec() })
    }

    /// `count` invocations of entry `entry` (its index in `new`'s entries).
    pub fn run(
        &self,
        gpu: &Gpu,
        entry: usize,
        params: &[[f32; 4]],
        points: &[[f32; 4]],
        count: u32,
    ) -> Vec<[f32; 4]> {
        let buffers = KernelBuffers::new(gpu, params, points, count);
        let group = buffers.group(gpu, &self.layout);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipelines[entry]);
            pass.set_bind_group(0, &group, &[]);
            dispatch(&mut pass, count);
        }
        gpu.queue.submit([encoder.finish()]);
        buffers.read(gpu)
    }
}

/// Dispatches `count` invocations in workgroups of 64, [`ROW_GROUPS`] per row.
pub fn dispatch(pass: &mut wgpu::ComputePass<'_>, count: u32) {
    let groups = count.div_ceil(64);
    pass.dispatch_workgroups(groups.min(ROW_GROUPS), groups.div_ceil(ROW_GROUPS), 1);
}

/// The three buffers of [`KERNEL_BINDINGS`] for one dispatch.
pub struct KernelBuffers {
    params: wgpu::Buffer,
    points: wgpu::Buffer,
    result: wgpu::Buffer,
}

impl KernelBuffers {
    pub fn new(gpu: &Gpu, params: &[[f32; 4]], points: &[[f32; 4]], count: u32) -> Self {
        let init = |label: &str, data: &[[f32; 4]]| {
            let data: &[[f32; 4]] = if data.is_empty() { &[[0.0; 4]] } else { data };
            gpu.buffer_init(label, bytemuck::cast_slice(data), wgpu::BufferUsages::STORAGE)
        };
        let result = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("chi2 result"),
            size: count.max(1) as u64 * 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Self { params: init("chi2 params", params), points: init("chi2 points", points), result }
    }

    /// A bind group of the three buffers on `layout`.
    pub fn group(&self, gpu: &Gpu, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        compute::buffer_group(
            gpu,
            "chi2 kernel",
            layout,
            &[&self.params, &self.points, &self.result],
        )
    }

    /// The results (after the dispatch was submitted).
    pub fn read(&self, gpu: &Gpu) -> Vec<[f32; 4]> {
        render::readback::read_pod(gpu, &self.result, "chi2 result").expect("chi2 readback")
    }
}

/// u32 bits in an f32 lane of a parameter vector (the kernel reads them with `bitcast<u32>`).
pub fn bits(x: u32) -> f32 {
    f32::from_bits(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A known sampler (uniform on the sphere, f64) passes; the same with a pdf that is off by
    /// 5% on one hemisphere fails.
    #[test]
    fn accepts_a_right_pdf_and_rejects_a_wrong_one() {
        let bins = SphereBins { theta: 16, phi: 32 };
        let draws = 200_000u64;
        let mut rng = render::scene::SplitMix64::new(3);
        let mut next = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let samples: Vec<([f32; 3], bool)> = (0..draws)
            .map(|_| {
                let z = 1.0 - 2.0 * next();
                let phi = 2.0 * PI * next();
                let r = (1.0 - z * z).max(0.0).sqrt();
                ([(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32], true)
            })
            .collect();
        let observed = bins.histogram(samples);
        let right = bins.integrate(&observed, &mut |d| vec![1.0 / (4.0 * PI); d.len()]);
        let o = assert_fits("uniform sphere", &observed, &right, draws);
        assert!((o.integral - 1.0).abs() < 1e-6, "{}", o.integral);
        let wrong = bins.integrate(&observed, &mut |d| {
            d.iter().map(|d| if d[2] > 0.0 { 1.05 } else { 0.95 } / (4.0 * PI)).collect()
        });
        assert!(test(&observed, &wrong, draws).unwrap().p_value < per_test_level());
    }

    /// A lobe as narrow as GGX's at roughness 0.05 (tan(θ'/2) distributed as tan θ_h of the
    /// GGX NDF of α = 0.003) around a slanted axis, drawn in f64: the lobe bins accept it, its
    /// pdf integrates to 1 on them, and the same pdf with α 3% wider fails.
    #[test]
    fn lobe_bins_resolve_a_narrow_lobe() {
        let axis = [-0.6f64, 0.0, 0.8];
        let bins = LobeBins { axis, scale: 0.003, theta: 32, phi: 64 };
        let [t, b, a] = bins.frame();
        let draws = 1u64 << 20;
        let mut rng = render::scene::SplitMix64::new(5);
        let mut next = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let alpha = 0.003f64;
        let samples: Vec<([f32; 3], bool)> = (0..draws)
            .map(|_| {
                let v = next();
                let theta = 2.0 * (alpha * (v / (1.0 - v)).sqrt()).atan();
                let phi = 2.0 * PI * next();
                let (st, ct) = theta.sin_cos();
                let (lx, ly) = (st * phi.cos(), st * phi.sin());
                (std::array::from_fn(|k| (lx * t[k] + ly * b[k] + ct * a[k]) as f32), true)
            })
            .collect();
        let observed = bins.histogram(samples);
        let pdf_of = |alpha: f64| {
            move |d: &[[f32; 3]]| -> Vec<f64> {
                d.iter()
                    .map(|d| {
                        let d = d.map(f64::from);
                        let dot = |u: [f64; 3]| u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
                        let theta = dot(t).hypot(dot(b)).atan2(dot(a));
                        let m = (0.5 * theta).tan() / alpha;
                        let p = 2.0 * m / (1.0 + m * m).powi(2) * (1.0 + alpha * alpha * m * m)
                            / (2.0 * alpha);
                        p / (2.0 * PI * theta.sin().max(1e-300))
                    })
                    .collect()
            }
        };
        let right = bins.integrate(&observed, &mut pdf_of(alpha));
        let o = assert_fits("narrow lobe", &observed, &right, draws);
        assert!((o.integral - 1.0).abs() < 1e-4, "{}", o.integral);
        let wrong = bins.integrate(&observed, &mut pdf_of(1.03 * alpha));
        assert!(test(&observed, &wrong, draws).unwrap().p_value < per_test_level());
    }

    #[test]
    fn cosine_integrates_to_one_on_the_bins() {
        // The pdf jumps at the horizon (a bin edge) and the quadrature integrates it exactly.
        let bins = SphereBins { theta: 32, phi: 64 };
        let i = bins.integrate(&[0.0; 2048], &mut |d| {
            d.iter().map(|d| (d[2] as f64).max(0.0) / PI).collect()
        });
        let total: f64 = i.iter().sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
    }

    #[test]
    fn samples_where_the_pdf_is_zero_are_an_error() {
        let e = test(&[1.0, 10.0, 10.0], &[0.0, 0.5, 0.5], 20).unwrap_err();
        assert!(e.contains("pdf integrates to 0"), "{e}");
    }
}
