//! Chi-square goodness-of-fit tests (testkit::chi2) of the two free-flight distance samplers, run
//! in their WGSL through small test kernels:
//!
//! - the subsurface random walk's chromatic free flight (media_free_flight.wgsl, called by
//!   media_subsurface_path.wgsl): a channel drawn from the throughput's shares q, then
//!   Exp(σ_t[c]); its distances against the mixture pdf Σ q σ_t e^{−σ_t t} that the walk divides
//!   a scattering vertex's throughput by, and the draws beyond a boundary at distance L against
//!   the survival Σ q e^{−σ_t L} it divides a boundary crossing by (tests/chi2/free_flight_kernel.wgsl);
//! - delta tracking (Woodcock) against the super-voxel majorants (media_tracking.wgsl's
//!   `delta_tracking`, the volume path tracer's free-flight sampler) through a baked
//!   heterogeneous cloud: the first real collision has density σ_t(t) T(t) on the segment, whose
//!   integral over a bin [a, b] is T(a) − T(b) exactly, with T from regular tracking's exact
//!   optical depth of the nearest-neighbour grid (media::regular_tracking); the rays that leave
//!   the segment are one more cell, expected T(t1) (tests/chi2/delta_tracking_kernel.wgsl).
//!
//! The escapes are a cell of the chi-square statistic, so a wrong survival or escape fraction
//! fails it as a wrong density does. Sizes: 2^20 draws per configuration, 64 bins plus the
//! escape cell; three configurations of each sampler.

use glam::{UVec3, Vec3};
use media::gpu::{GpuMedium, RaySegment};
use media::{DensityGrid, DensityKind, Medium, Segment};
use render::pass_library::PassLibrary;
use render::shader::{Module, Program};
use testkit::chi2::{self, IntervalBins, Kernel};
use testkit::test_scenes::gpu;

const DRAWS: u32 = 1 << 20;

/// A Chi-square test over `bins` (valid draws) plus one cell of `escapes` expected
/// `escape_mass`: the draws beyond the binned range.
fn assert_fits_with_escapes(
    what: &str,
    mut observed: Vec<f64>,
    mut integral: Vec<f64>,
    escapes: f64,
    escape_mass: f64,
) {
    observed.push(escapes);
    integral.push(escape_mass);
    let o = chi2::assert_fits(what, &observed, &integral, DRAWS as u64);
    eprintln!(
        "{what}: chi2 {:.1} dof {} p {:.3} integral {:.6}; escaped {:.5} expected {:.5}",
        o.statistic,
        o.dof,
        o.p_value,
        o.integral,
        escapes / DRAWS as f64,
        escape_mass
    );
}

/// (σ_t, throughput, L): the channels' extinctions, the throughput that sets the channel
/// probabilities, the distance to the boundary.
const CHROMATIC: [([f32; 3], [f32; 3], f32); 3] = [
    ([2.0, 5.0, 20.0], [1.0, 1.0, 1.0], 1.5),
    ([2.0, 5.0, 20.0], [0.2, 0.5, 1.3], 0.3),
    ([0.5, 8.0, 3.0], [3.0, 0.1, 1.0], 2.0),
];

fn free_flight_kernel() -> Kernel {
    let source = Module {
        path: "package::media::chi2_free_flight_kernel".into(),
        file: "media/tests/chi2/free_flight_kernel.wgsl".into(),
        source: include_str!("chi2/free_flight_kernel.wgsl").into(),
    };
    Kernel::new(
        gpu(),
        "package::media::chi2_bindings",
        vec![
            PassLibrary::module("package::pt_sampling"),
            render::wgsl_file!("media_free_flight.wgsl"),
        ],
        source,
        ["free_flight_sample_main", "free_flight_pdf_main"],
    )
    .expect("the free-flight test kernel compiles")
}

/// Distances binned in x = ln(1 + t/d) / ln(1 + L/d), d the shortest mean free path: the
/// densest channel's decay spans many bins, the slowest one's tail the rest.
struct LogBins {
    d: f64,
    span: f64,
}

impl LogBins {
    fn new(sigma_t: [f32; 3], l: f32) -> Self {
        let d = 1.0 / sigma_t.iter().copied().fold(0.0f32, f32::max) as f64;
        Self { d, span: (1.0 + l as f64 / d).ln() }
    }
    fn x(&self, t: f64) -> f64 {
        (1.0 + t / self.d).ln() / self.span
    }
    fn t(&self, x: f64) -> f64 {
        self.d * ((x * self.span).exp() - 1.0)
    }
    /// dt/dx.
    fn jacobian(&self, x: f64) -> f64 {
        self.span * (self.t(x) + self.d)
    }
}

#[test]
fn subsurface_chromatic_free_flight_fits_the_mixture_pdf() {
    let k = free_flight_kernel();
    let bins = IntervalBins { lo: 0.0, hi: 1.0, bins: 64 };
    for (seed, &(sigma_t, beta, l)) in CHROMATIC.iter().enumerate() {
        let u = chi2::bits;
        let params = [
            [sigma_t[0], sigma_t[1], sigma_t[2], 0.0],
            [beta[0], beta[1], beta[2], 0.0],
            [u(DRAWS), u(seed as u32 + 1), 0.0, 0.0],
        ];
        let eval = |ts: &[f64]| -> Vec<[f32; 4]> {
            let points: Vec<[f32; 4]> = ts.iter().map(|&t| [t as f32, 0.0, 0.0, 0.0]).collect();
            let mut params = params;
            params[2][0] = u(points.len() as u32);
            k.run(gpu(), 1, &params, &points, points.len() as u32)
        };
        let warp = LogBins::new(sigma_t, l);
        let drawn = k.run(gpu(), 0, &params, &[], DRAWS);
        let escapes = drawn.iter().filter(|r| r[0] as f64 > l as f64).count() as f64;
        let observed = bins.histogram(drawn.iter().filter(|r| r[0] as f64 <= l as f64).map(|r| {
            let t = r[0] as f64;
            (warp.x(t).clamp(0.0, 1.0), t.is_finite() && t >= 0.0)
        }));
        let integral = bins.integrate(&observed, &mut |xs| {
            let ts: Vec<f64> = xs.iter().map(|&x| warp.t(x)).collect();
            eval(&ts).iter().zip(xs).map(|(r, &x)| r[0] as f64 * warp.jacobian(x)).collect()
        });
        let survival = eval(&[l as f64])[0][1] as f64;
        let what =
            format!("WGSL chromatic free flight, σ_t {sigma_t:?}, throughput {beta:?}, L {l}");
        assert_fits_with_escapes(&what, observed, integral, escapes, survival);
    }
}

/// A cloud baked at 32³ voxels over [−1, 1]³ (2³ super-voxels of 16³), peak σ_t `PEAK`.
const PEAK: f32 = 1.5;

fn cloud() -> Medium {
    Medium::new(DensityGrid::bake(
        &DensityKind::Cloud { octaves: 4, frequency: 3.0, seed: 7 },
        UVec3::splat(32),
        PEAK,
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
    ))
}

/// (origin, direction, t_max): through the centre, off-centre and diagonal, one stopping inside.
fn segments(m: &Medium) -> Vec<Segment> {
    [
        (Vec3::new(-2.0, 0.05, 0.02), Vec3::X, 10.0),
        (Vec3::new(-1.5, -1.5, 0.3), Vec3::new(1.0, 1.0, -0.2), 10.0),
        (Vec3::new(0.1, -2.0, -0.25), Vec3::new(0.1, 1.0, 0.15), 2.4),
    ]
    .into_iter()
    .map(|(o, d, t_max)| m.segment(o, d.normalize(), t_max).expect("the ray meets the box"))
    .collect()
}

struct DeltaKernel {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl DeltaKernel {
    fn new(medium: &GpuMedium) -> Self {
        let source = Module {
            path: "package::media::chi2_delta_tracking_kernel".into(),
            file: "media/tests/chi2/delta_tracking_kernel.wgsl".into(),
            source: include_str!("chi2/delta_tracking_kernel.wgsl").into(),
        };
        // The medium is @group(0), as in the media passes; the kernel's buffers @group(1).
        let bindings = render::compute::group_module(
            "package::media::chi2_bindings",
            1,
            &chi2::KERNEL_BINDINGS,
            &[],
        );
        let program = chi2::with_replacements(
            Program::new(media::gpu::modules()).with([bindings]).entry(source),
        );
        let layout = render::compute::binding_layout(gpu(), "chi2 delta", &chi2::KERNEL_BINDINGS);
        let [pipeline] = render::compute::pipelines(
            gpu(),
            "chi2 delta",
            &program,
            &[&medium.layout, &layout],
            ["delta_tracking_main"],
        )
        .expect("the delta tracking test kernel compiles");
        Self { layout, pipeline }
    }

    fn run(&self, medium: &GpuMedium, params: &[[f32; 4]]) -> Vec<[f32; 4]> {
        let gpu = gpu();
        let buffers = chi2::KernelBuffers::new(gpu, params, &[], DRAWS);
        let group = buffers.group(gpu, &self.layout);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &medium.group, &[]);
            pass.set_bind_group(1, &group, &[]);
            chi2::dispatch(&mut pass, DRAWS);
        }
        gpu.queue.submit([encoder.finish()]);
        buffers.read(gpu)
    }
}

#[test]
fn delta_tracking_fits_the_collision_density_and_transmittance() {
    let m = cloud();
    let gm = GpuMedium::new(gpu(), &m);
    let k = DeltaKernel::new(&gm);
    for (seed, s) in segments(&m).iter().enumerate() {
        let r = RaySegment::from(s);
        let params = [
            [r.origin[0], r.origin[1], r.origin[2], r.t0],
            [r.dir[0], r.dir[1], r.dir[2], r.t1],
            [chi2::bits(DRAWS), chi2::bits(1000 + seed as u32), 0.0, 0.0],
        ];
        let drawn = k.run(&gm, &params);
        let bins = IntervalBins { lo: s.t0 as f64, hi: s.t1 as f64, bins: 64 };
        let escapes = drawn.iter().filter(|r| r[1] > 0.5).count() as f64;
        // f32 rounding may put a collision a hair outside [t0, t1]: it belongs to the end bin.
        let observed = bins.histogram(
            drawn
                .iter()
                .filter(|r| r[1] < 0.5)
                .map(|r| ((r[0] as f64).clamp(bins.lo, bins.hi), true)),
        );
        // T at every bin edge, from the exact optical depth of [t0, edge].
        let transmittance: Vec<f64> = (0..=bins.bins)
            .map(|e| {
                let t1 = if e == bins.bins {
                    s.t1
                } else {
                    (bins.lo + (bins.hi - bins.lo) * e as f64 / bins.bins as f64) as f32
                };
                (-media::regular_tracking::optical_depth(&m, &Segment { t1, ..*s })).exp()
            })
            .collect();
        let integral: Vec<f64> = transmittance.windows(2).map(|w| w[0] - w[1]).collect();
        let what = format!(
            "WGSL delta tracking, segment [{:.3}, {:.3}] of {:?} + t {:?}",
            s.t0, s.t1, s.origin, s.dir
        );
        assert_fits_with_escapes(&what, observed, integral, escapes, transmittance[bins.bins]);
    }
}
