//! The closed-form setting of `media::closed_form` on the GPU (media_closed_form_trials.wgsl):
//! one trial per seed, the WGSL jackknife and naive estimate on the same random numbers as the
//! CPU twin. Needs no medium.

use render::compute::{BufferBinding, binding_layout, pipelines};
use render::error::RenderError;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::shader::{Module, Program};

use super::closed_form::ErrorDistribution;

render::gpu_struct! {
    pub struct ClosedFormParams {
        pub tau: f32 => "f32",
        pub sigma: f32 => "f32",
        pub kind: u32 => "u32",
        pub count: u32 => "u32",
    }
}

const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("cf_params", "ClosedFormParams"),
    BufferBinding::read("seeds", "array<u32>"),
    BufferBinding::read_write("trials", "array<vec2f>"),
];

pub struct ClosedFormPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ClosedFormPass {
    pub fn new(gpu: &Gpu) -> Result<Self, RenderError> {
        let layout = binding_layout(gpu, "media closed-form trials", &BINDINGS);
        let types =
            Module::generated("package::media::closed_form_types", &[ClosedFormParams::WGSL]);
        let bindings = render::compute::group_module(
            "package::media::closed_form_bindings",
            0,
            &BINDINGS,
            &[&types],
        );
        let program = Program::new(vec![
            render::wgsl_file!("media_rng.wgsl"),
            render::wgsl_file!("media_jackknife.wgsl"),
            types,
            bindings,
        ])
        .entry(super::module("closed_form_trials", include_str!("closed_form_trials.wgsl")));
        let [pipeline] = pipelines(
            gpu,
            "media closed-form trials",
            &program,
            &[&layout],
            ["closed_form_trials"],
        )?;
        Ok(Self { layout, pipeline })
    }

    /// (K, exp(−X̄)) per seed.
    pub fn run(
        &self,
        gpu: &Gpu,
        dist: ErrorDistribution,
        tau: f32,
        sigma: f32,
        seeds: &[u32],
    ) -> Result<Vec<(f32, f32)>, String> {
        let params = ClosedFormParams { tau, sigma, kind: dist as u32, count: seeds.len() as u32 };
        let raw: Vec<[f32; 2]> = super::trials::run_trials(
            gpu,
            "media closed-form trials",
            &self.layout,
            &self.pipeline,
            bytemuck::bytes_of(&params),
            seeds,
        )?;
        Ok(raw.into_iter().map(|v| (v[0], v[1])).collect())
    }
}
