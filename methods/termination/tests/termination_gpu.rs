//! The termination decision on the GPU (shaders/decision.wgsl) against the CPU
//! reference (termination::decide) on the same inputs.

use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::Staging;
use render::scene::SplitMix64;
use render::shader::{Module, Program};
use termination::gpu_decision::{decision_module, rule_words};
use termination::{LocalStats, PathState, TerminationRule, decide};

fn rules() -> Vec<TerminationRule> {
    vec![
        TerminationRule::VarianceBounding { t: 0.01, relative: false },
        TerminationRule::VarianceBounding { t: 1.0, relative: false },
        TerminationRule::VarianceBounding { t: 0.1, relative: true },
        TerminationRule::MseMinimisation { s: 100.0, margin: 1.1, bias_clamp: 0.1 },
        TerminationRule::MseMinimisation { s: 1.0, margin: 1.5, bias_clamp: 0.1 },
        TerminationRule::AreaSpread { c: 0.01 },
        TerminationRule::AreaSpread { c: 100.0 },
        TerminationRule::FirstVertex,
        TerminationRule::PathTracing,
    ]
}

#[test]
fn gpu_decision_matches_the_cpu_reference() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let mut rng = SplitMix64::new(7);
    // Log-uniform magnitudes over 6 decades: the cases straddle every rule's boundary.
    let mut mag = |lo: f64| lo * 10f64.powf(6.0 * rng.next_f32() as f64);
    let mut cases = Vec::new();
    for rule in rules() {
        for survival in [1.0, 0.6, 0.2] {
            for _ in 0..200 {
                let stats = LocalStats {
                    radiance: mag(1e-3),
                    variance: mag(1e-4),
                    continuation2: mag(1e-4),
                    bias2: mag(1e-5),
                    deferred_bias2: mag(1e-6),
                };
                // One case in four has no filled record at the first hit.
                let first_filled = mag(1.0) > 10.0f64.powf(1.5);
                let threshold = match rule {
                    TerminationRule::VarianceBounding { .. } => {
                        termination::path_threshold(&rule, first_filled.then_some(stats.radiance))
                    }
                    _ => 0.0,
                };
                let state = PathState {
                    throughput2: mag(1e-3),
                    path_variance: if threshold.is_finite() {
                        threshold * 0.5 * (mag(1e-6) / 1e0).min(1.0)
                    } else {
                        mag(1e-6)
                    },
                    threshold,
                    spread_sqrt: mag(1e-3),
                    spread0: mag(1e-3),
                    vertex: 1 + (mag(1.0) as u32 % 4),
                };
                cases.push(DecisionCase { rule, survival, state, stats, first_filled });
            }
        }
    }
    let gpu_out = decide_on_gpu(&gpu, &cases).unwrap();
    let (mut kinds, mut mismatches) = ([0usize; 3], Vec::new());
    for (c, g) in cases.iter().zip(&gpu_out) {
        let mut state = c.state;
        let alpha = decide(&c.rule, c.survival, &mut state, &c.stats).alpha();
        kinds[if alpha == 1.0 {
            0
        } else if alpha == 0.0 {
            1
        } else {
            2
        }] += 1;
        let close = |a: f64, b: f32| (a - b as f64).abs() <= 1e-4 * a.abs().max(1e-6);
        // The threshold as tc_trace takes it from the first hit (f32: "infinite" is 3e38).
        let threshold =
            termination::path_threshold(&c.rule, c.first_filled.then_some(c.stats.radiance));
        let same_threshold =
            if threshold.is_finite() { close(threshold, g[2]) } else { g[2] >= 1e38 };
        if !close(alpha, g[0]) || !close(state.path_variance, g[1]) || !same_threshold {
            mismatches.push(format!(
                "{:?}: cpu ({alpha}, {}, {threshold}) gpu ({}, {}, {})",
                c, state.path_variance, g[0], g[1], g[2]
            ));
        }
    }
    // The batch must exercise every outcome: continue, terminate and blend.
    assert!(kinds.iter().all(|&k| k > 50), "outcomes continue/terminate/blend: {kinds:?}");
    // f32 against f64: a case within rounding of a boundary may flip; allow at most 0.5%.
    assert!(
        mismatches.len() * 200 <= cases.len(),
        "{} of {} cases differ:\n{}",
        mismatches.len(),
        cases.len(),
        mismatches.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
}

/// One case: the rule, roulette survival, the path state at the vertex and the local stats.
#[derive(Clone, Copy, Debug)]
pub struct DecisionCase {
    pub rule: TerminationRule,
    pub survival: f64,
    pub state: PathState,
    pub stats: LocalStats,
    /// Whether the path's first hit had a filled record (the relative threshold's brightness
    /// is then `stats.radiance`).
    pub first_filled: bool,
}

/// (α, path variance after the decision, the path's threshold from `tc_threshold`) per case,
/// computed by `tc_decide` in f32.
pub fn decide_on_gpu(gpu: &Gpu, cases: &[DecisionCase]) -> Result<Vec<[f32; 3]>, RenderError> {
    let mut words: Vec<[f32; 4]> = Vec::with_capacity(cases.len() * 6);
    for c in cases {
        let (kind, relative, param, margin, clamp) = rule_words(&c.rule);
        let (s, st) = (&c.state, &c.stats);
        words.push([f32::from_bits(kind), f32::from_bits(relative), param, margin]);
        words.push([clamp, c.survival as f32, 0.0, 0.0]);
        words.push([
            s.throughput2 as f32,
            s.path_variance as f32,
            s.threshold as f32,
            s.spread_sqrt as f32,
        ]);
        words.push([s.spread0 as f32, f32::from_bits(s.vertex), 0.0, 0.0]);
        words.push([
            st.radiance as f32,
            st.variance as f32,
            st.continuation2 as f32,
            st.bias2 as f32,
        ]);
        words.push([st.deferred_bias2 as f32, c.first_filled as u32 as f32, 0.0, 0.0]);
    }
    let device = &gpu.device;
    // The probe's entry point lives beside this test, not in the crate's shaders/.
    let probe = Module::file(
        env!("CARGO_PKG_NAME"),
        "decision_probe.wgsl",
        include_str!("decision_probe.wgsl"),
    );
    let program = Program::new(vec![decision_module()]).entry(probe);
    let [pipeline] = render::compute::pipelines_auto_layout(
        gpu,
        "tc_decide_probe",
        &program,
        ["tc_decide_probe"],
    )?;
    let input = gpu.buffer_init(
        "decision cases",
        bytemuck::cast_slice(&words),
        wgpu::BufferUsages::STORAGE,
    );
    let size = (cases.len().max(1) * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("decisions"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("decision probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
        ],
    });
    let mut encoder = device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("decision probe") });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tc_decide_probe"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
    }
    let staging = Staging::copy_of(gpu, &mut encoder, &output, "decisions");
    gpu.queue.submit([encoder.finish()]);
    let out: Vec<[f32; 4]> = staging.read(gpu)?;
    Ok(out.into_iter().take(cases.len()).map(|v| [v[0], v[1], v[2]]).collect())
}
