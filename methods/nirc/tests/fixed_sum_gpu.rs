//! The WGSL fixed-point sums (shaders/fixed_sum.wgsl) against the CPU mirror (src/fixed_sum.rs),
//! word for word: values across every exponent the format takes, both signs, the refused ones,
//! and many values into few accumulators so that carries cross the words both ways.

mod common;

use common::Rng;
use nirc::fixed_sum::FixedSum;
use render::compute::{buffer_group, pipelines_auto_layout};
use render::gpu::Gpu;
use render::shader::{Module, Program};
use wgpu::util::DeviceExt;

const ACCUMULATORS: usize = 7;

const ENTRY: &str = "
import package::nirc::fixed_sum::{fixed_add};
@group(0) @binding(0) var<storage, read> values: array<f32>;
@group(0) @binding(2) var<storage, read_write> accepted: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i < arrayLength(&values) {
        accepted[i] = select(0u, 1u, fixed_add(3u * (i % ACCUMULATORS), values[i]));
    }
}
";

/// Sums `values` on the GPU, value i into accumulator i % ACCUMULATORS; the accumulators' words
/// and whether each value was accepted.
fn gpu_sums(gpu: &Gpu, values: &[f32]) -> (Vec<[u32; 3]>, Vec<bool>) {
    let program = Program::new(vec![
        Module::generated("package::nirc::types", &[&nirc::gpu::shaders::structs()]),
        Module::generated(
            "package::nirc::bindings",
            &["@group(0) @binding(1) var<storage, read_write> accum: array<atomic<u32>>;"],
        ),
        render::wgsl_file!("bindings_common.wgsl"),
        render::wgsl_file!("fixed_sum.wgsl"),
    ])
    .entry(Module::generated(
        "package::fixed_sum_probe",
        &[ENTRY, &format!("const ACCUMULATORS: u32 = {ACCUMULATORS}u;")],
    ));
    let [pipeline] = pipelines_auto_layout(gpu, "fixed_sum_probe", &program, ["main"]).unwrap();
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    let device = &gpu.device;
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("values"),
        contents: bytemuck::cast_slice(values),
        usage,
    });
    let accum = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("accum"),
        contents: &[0u8; ACCUMULATORS * 12],
        usage,
    });
    let accepted = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("accepted"),
        contents: &vec![0u8; values.len() * 4],
        usage,
    });
    let group = buffer_group(
        gpu,
        "fixed_sum_probe",
        &pipeline.get_bind_group_layout(0),
        &[&input, &accum, &accepted],
    );
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((values.len() as u32).div_ceil(64), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let words: Vec<u32> = render::readback::read_pod(gpu, &accum, "accum").unwrap();
    let flags: Vec<u32> = render::readback::read_pod(gpu, &accepted, "accepted").unwrap();
    (words.chunks(3).map(|w| [w[0], w[1], w[2]]).collect(), flags.iter().map(|&f| f == 1).collect())
}

#[test]
fn gpu_fixed_sums_equal_the_cpu_word_for_word() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let mut values = vec![
        0.0,
        -0.0,
        1.0e-40, // subnormal: below 2^-48, adds nothing
        f32::powi(2.0, -48),
        -f32::powi(2.0, -48),
        f32::powi(2.0, -49),
        1.0,
        -1.0,
        f32::powi(2.0, 7), // its mantissa starts exactly at the middle word's bit 0 (shift 32)
        -f32::powi(2.0, 8), // one bit further (shift 33), negated; no value reaches the top word at bit 0
        f32::powi(2.0, 31),
        -4_294_967_040.0, // largest accepted magnitude
        4_294_967_296.0,  // 2^32: refused
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ];
    // Random magnitudes over 2^-60 .. 2^33 (so some are refused and some truncate to nothing),
    // both signs, random mantissas.
    let mut rng = Rng(71);
    for _ in 0..4000 {
        let exponent = rng.range(-60.0, 33.0).floor() as i32;
        let sign = if rng.f32() < 0.5 { -1.0 } else { 1.0 };
        values.push(sign * (1.0 + rng.f32()) * f32::powi(2.0, exponent));
    }
    // Many small values around zero, so the sums cross zero and carry through all-ones words.
    for i in 0..3000 {
        values.push(if i % 2 == 0 { 3.0e-6 } else { -2.9e-6 } * (1.0 + rng.f32()));
    }
    let (words, accepted) = gpu_sums(&gpu, &values);
    let mut cpu = vec![FixedSum::default(); ACCUMULATORS];
    for (i, &x) in values.iter().enumerate() {
        assert_eq!(
            cpu[i % ACCUMULATORS].add(x),
            accepted[i],
            "value {i} ({x:e}): accepted on the CPU and the GPU alike"
        );
    }
    assert!(accepted.iter().filter(|a| !**a).count() >= 4, "the refused values are refused");
    for (a, (g, c)) in words.iter().zip(&cpu).enumerate() {
        assert_eq!(
            *g,
            c.words(),
            "accumulator {a}: GPU {g:08x?} against the CPU's {:08x?}",
            c.words()
        );
    }
    // The sums are not trivially zero: the test would pass on a shader that adds nothing.
    assert!(cpu.iter().all(|c| *c != FixedSum::default()));
}
