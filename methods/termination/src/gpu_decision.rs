//! The WGSL decision (shaders/termination/decision.wgsl) run on a batch of cases, for the
//! GPU-vs-CPU test of the termination decision.

use super::decision::{LocalStats, PathState};
use super::rule::TerminationRule;
use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::Staging;
use render::shader::{Module, Program};

/// `package::termination::decision`: the decision, imported by the cache's passes and the probe.
pub fn decision_module() -> Module {
    render::wgsl_file!("decision.wgsl")
}

/// The rule as the shader's `TcRule` fields: (kind, relative, param, margin, bias_clamp).
pub fn rule_words(rule: &TerminationRule) -> (u32, u32, f32, f32, f32) {
    match *rule {
        TerminationRule::VarianceBounding { t, relative } => {
            (0, relative as u32, t as f32, 1.0, 0.0)
        }
        TerminationRule::MseMinimisation { s, margin, bias_clamp } => {
            (1, 0, s as f32, margin as f32, bias_clamp as f32)
        }
        TerminationRule::AreaSpread { c } => (2, 0, c as f32, 1.0, 0.0),
        TerminationRule::FirstVertex => (3, 0, 0.0, 1.0, 0.0),
        TerminationRule::PathTracing => (4, 0, 0.0, 1.0, 0.0),
    }
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
    let program =
        Program::new(vec![decision_module()]).entry(render::wgsl_file!("decision_probe.wgsl"));
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
