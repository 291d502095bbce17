//! The closed-form MIS setting of `media::mis_trial` on the GPU (media_mis_trials.wgsl): one trial
//! per seed, the WGSL weights and Eqs. 9/10 on the same random numbers as the CPU reference. Needs
//! no medium: its program is the random numbers, the jackknife and the MIS library only.

use render::compute::{BufferBinding, binding_layout, pipelines};
use render::error::RenderError;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::shader::{Module, Program};

use super::mis_trial::{MisSetup, MisTrial};

render::gpu_struct! {
    pub struct MisParams {
        pub mu: f32 => "f32",
        pub majorant: f32 => "f32",
        pub t_max: f32 => "f32",
        pub delta: f32 => "f32",
        pub d: f32 => "f32",
        pub sigma_rel: f32 => "f32",
        pub count: u32 => "u32",
        pub _pad: u32 => "u32",
    }
}

const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("mis_params", "MisParams"),
    BufferBinding::read("seeds", "array<u32>"),
    BufferBinding::read_write("trials", "array<vec4f>"),
];

pub struct MisPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl MisPass {
    pub fn new(gpu: &Gpu) -> Result<Self, RenderError> {
        let layout = binding_layout(gpu, "media mis trials", &BINDINGS);
        let types = Module::generated("package::media::mis_trials_types", &[MisParams::WGSL]);
        let bindings = render::compute::group_module(
            "package::media::mis_trials_bindings",
            0,
            &BINDINGS,
            &[&types],
        );
        let program = Program::new(vec![
            render::wgsl_file!("media_rng.wgsl"),
            render::wgsl_file!("media_jackknife.wgsl"),
            render::wgsl_file!("media_mis.wgsl"),
            types,
            bindings,
        ])
        .entry(super::module("mis_trials", include_str!("mis_trials.wgsl")));
        let [pipeline] = pipelines(gpu, "media mis trials", &program, &[&layout], ["mis_trials"])?;
        Ok(Self { layout, pipeline })
    }

    pub fn run(&self, gpu: &Gpu, setup: &MisSetup, seeds: &[u32]) -> Result<Vec<MisTrial>, String> {
        let s = setup;
        let params = MisParams {
            mu: s.mu,
            majorant: s.majorant,
            t_max: s.t_max,
            delta: s.delta,
            d: s.d,
            sigma_rel: s.sigma_rel,
            count: seeds.len() as u32,
            _pad: 0,
        };
        let raw: Vec<[f32; 8]> = super::trials::run_trials(
            gpu,
            "media mis trials",
            &self.layout,
            &self.pipeline,
            bytemuck::bytes_of(&params),
            seeds,
        )?;
        Ok(raw
            .into_iter()
            .map(|v| MisTrial {
                w1: [v[0], v[1], v[2]],
                eq9: [v[3], v[4], v[5]],
                eq10: [v[6], v[7]],
            })
            .collect())
    }
}
