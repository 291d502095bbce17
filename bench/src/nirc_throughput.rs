//! Throughput benchmark of the GPU cache (not a test): training and inference per second and in
//! GFLOP/s against the adapter's FMA ceiling measured in the same run, and the cost of
//! evaluating both predictors + blend over EMA-only.

use std::time::Instant;

use nirc::gpu::shaders::WeightPlacement;
use nirc::gpu::{NeuralCache, answer_buffer, readback, upload};
use nirc::{
    CacheQuery, CacheState, NircCacheSettings, NircError, PredictorMode, SceneBounds,
    TrainingRecord,
};
use render::gpu::Gpu;
use wgpu::util::DeviceExt;

#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchReport {
    pub adapter: String,
    pub placement: WeightPlacement,
    pub width: u32,
    pub hidden_layers: u32,
    pub batch: u32,
    pub queries: u32,
    /// The adapter's FMA ceiling (fma_peak.wgsl), measured in the same run.
    pub peak_gflops: f64,
    pub train_records_per_s: f64,
    /// Useful MLP FLOPs of training per second: 2 x the multiply-adds of the High-LR forward,
    /// backward and weight gradient (3 x a forward) per record; the EMA forward that feeds the
    /// reliability samples, the encoding, Adam and the grid are not counted but are timed.
    pub train_gflops: f64,
    pub train_percent_of_peak: f64,
    pub ema_only_queries_per_s: f64,
    pub blend_queries_per_s: f64,
    /// EMA-only inference: 2 x the forward's multiply-adds per query.
    pub infer_gflops: f64,
    pub infer_percent_of_peak: f64,
    /// Extra time of the blend over EMA-only inference, in percent of one training step of
    /// `batch` records plus EMA-only inference of `queries` (no camera paths; `flicker bench
    /// --nirc` measures whole frames as well, crate::nirc_frames).
    pub blend_overhead_step_percent: f64,
    /// Extra time of the blend over EMA-only inference, in percent of EMA-only inference.
    pub blend_overhead_infer_percent: f64,
    /// One 64x64 layer as a tiled product, 4 records x 16 outputs per invocation (the
    /// training pass's shape) and 16 x 16 (tile_layer.wgsl).
    pub layer_probe_4x16_gflops: f64,
    pub layer_probe_16x16_gflops: f64,
    /// Milliseconds per stage of one training step, each stage submitted alone.
    pub train_stages_ms: Vec<(String, f64)>,
    /// The same training step with sparse grid updates (`optimizer.sparse_grid`), timed right
    /// after the dense one on the same records: records/s, GFLOP/s (counted as `train_gflops`),
    /// share of the ceiling, and its stages.
    pub train_sparse_records_per_s: f64,
    pub train_sparse_gflops: f64,
    pub train_sparse_percent_of_peak: f64,
    pub train_sparse_stages_ms: Vec<(String, f64)>,
    /// Grid quads the sparse step touched, of all grid quads.
    pub sparse_touched_quads: u32,
    pub grid_quads: u32,
}

fn records(n: u32) -> Vec<TrainingRecord> {
    let mut s = 0x1234_5678u32;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f32 / u32::MAX as f32
    };
    (0..n)
        .map(|_| {
            let p = [rnd(), rnd(), rnd()];
            let d =
                glam::Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(glam::Vec3::Z);
            TrainingRecord::new(p, d.into(), [p[0], p[1] * p[2], 0.5])
        })
        .collect()
}

fn time<F: FnMut() -> Result<(), NircError>>(
    gpu: &Gpu,
    reps: u32,
    mut f: F,
) -> Result<f64, NircError> {
    f()?; // warm-up (pipeline compilation, first touch)
    readback::wait_idle(gpu)?;
    let t = Instant::now();
    for _ in 0..reps {
        f()?;
    }
    readback::wait_idle(gpu)?;
    Ok(t.elapsed().as_secs_f64() / reps as f64)
}

/// Runs the benchmark with `config` (e.g. width 64) on `batch` training records and `queries`
/// queries, `reps` repetitions each.
pub fn run(
    gpu: &Gpu,
    config: &NircCacheSettings,
    placement: Option<WeightPlacement>,
    batch: u32,
    queries: u32,
    reps: u32,
) -> Result<BenchReport, NircError> {
    let mut config = config.clone();
    config.max_batch = config.max_batch.max(batch);
    // Warm-up 0 so that the blend really reads the reliability grid.
    config.reliability.warmup = 0;
    let state = CacheState::initial(&config, SceneBounds::new([0.0; 3], [1.0; 3]))?;
    let cache = NeuralCache::from_state(gpu, &state, placement)?;
    let recs = upload(gpu, "bench records", &records(batch));
    let train_s = time(gpu, reps, || cache.train(gpu, &recs, batch))?;
    let train_stages_ms = cache
        .train_stage_seconds(gpu, &recs, batch, reps)?
        .into_iter()
        .map(|(n, s)| (n.to_string(), 1e3 * s))
        .collect();
    // Sparse grid updates on the same records, timed the same way.
    let mut sparse_config = config.clone();
    sparse_config.optimizer.sparse_grid = true;
    let sparse_state = CacheState::initial(&sparse_config, SceneBounds::new([0.0; 3], [1.0; 3]))?;
    let sparse = NeuralCache::from_state(gpu, &sparse_state, placement)?;
    let train_sparse_s = time(gpu, reps, || sparse.train(gpu, &recs, batch))?;
    let train_sparse_stages_ms = sparse
        .train_stage_seconds(gpu, &recs, batch, reps)?
        .into_iter()
        .map(|(n, s)| (n.to_string(), 1e3 * s))
        .collect();
    let sparse_touched_quads = sparse.touched_grid_quads(gpu)?;
    drop(sparse);
    let q: Vec<CacheQuery> = records(queries).iter().map(|r| r.query()).collect();
    let qbuf = upload(gpu, "bench queries", &q);
    let out = answer_buffer(gpu, queries);
    let ema_s = time(gpu, reps, || cache.infer(gpu, &qbuf, queries, &out, PredictorMode::EmaOnly))?;
    let blend_s = time(gpu, reps, || cache.infer(gpu, &qbuf, queries, &out, PredictorMode::Blend))?;
    let probes = probes(gpu, reps)?;
    let flops = 2.0 * cache.layout.forward_macs() as f64;
    let train_gflops = batch as f64 * 3.0 * flops / train_s / 1e9;
    let train_sparse_gflops = batch as f64 * 3.0 * flops / train_sparse_s / 1e9;
    let infer_gflops = queries as f64 * flops / ema_s / 1e9;
    Ok(BenchReport {
        adapter: gpu.summary.to_string(),
        placement: cache.placement,
        width: config.network.width,
        hidden_layers: config.network.hidden_layers,
        batch,
        queries,
        peak_gflops: probes.fma_gflops,
        train_records_per_s: batch as f64 / train_s,
        train_gflops,
        train_percent_of_peak: 100.0 * train_gflops / probes.fma_gflops,
        ema_only_queries_per_s: queries as f64 / ema_s,
        blend_queries_per_s: queries as f64 / blend_s,
        infer_gflops,
        infer_percent_of_peak: 100.0 * infer_gflops / probes.fma_gflops,
        blend_overhead_step_percent: 100.0 * (blend_s - ema_s) / (train_s + ema_s),
        blend_overhead_infer_percent: 100.0 * (blend_s - ema_s) / ema_s,
        layer_probe_4x16_gflops: probes.layer_4x16_gflops,
        layer_probe_16x16_gflops: probes.layer_16x16_gflops,
        train_stages_ms,
        train_sparse_records_per_s: batch as f64 / train_sparse_s,
        train_sparse_gflops,
        train_sparse_percent_of_peak: 100.0 * train_sparse_gflops / probes.fma_gflops,
        train_sparse_stages_ms,
        sparse_touched_quads,
        grid_quads: cache.layout.grid_params() / 4,
    })
}

/// GFLOP/s of the probe kernels.
pub struct Probes {
    pub fma_gflops: f64,
    pub layer_4x16_gflops: f64,
    pub layer_16x16_gflops: f64,
}

fn dispatch_timed(
    gpu: &Gpu,
    reps: u32,
    pipeline: &wgpu::ComputePipeline,
    entries: &[(u32, &wgpu::Buffer)],
    groups: u32,
) -> Result<f64, NircError> {
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .iter()
        .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
        .collect();
    let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("nirc probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    time(gpu, reps, || {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("nirc probe") });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("nirc probe"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    })
}

/// Entry point `block{r}x{o}` of tile_layer.wgsl: r records x o outputs per invocation.
fn tile_layer_probe(r: u32, o: u32) -> String {
    let (rq, oq) = (r / 4, o / 4);
    let mut s = format!(
        "@compute @workgroup_size({inv})\nfn block{r}x{o}(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {{\n    load_tiles(wid.x, lid, {inv}u);\n    let rb = (lid % {per}u) * {rq}u;\n    let ob = (lid / {per}u) * {oq}u;\n",
        inv = (64 / r) * (64 / o),
        per = 64 / r
    );
    let accs: Vec<String> =
        (0..rq).flat_map(|a| (0..o).map(move |j| format!("c{a}_{j}"))).collect();
    for acc in &accs {
        s.push_str(&format!("    var {acc} = vec4<f32>(0.0);\n"));
    }
    s.push_str("    for (var k = 0u; k < 64u; k++) {\n");
    for a in 0..rq {
        s.push_str(&format!("        let a{a} = ta[k * 16u + rb + {a}u];\n"));
    }
    for q in 0..oq {
        s.push_str(&format!("        let w{q} = tw[k * 16u + ob + {q}u];\n"));
    }
    for a in 0..rq {
        for j in 0..o {
            s.push_str(&format!(
                "        c{a}_{j} += a{a} * w{}.{};\n",
                j / 4,
                ["x", "y", "z", "w"][j as usize % 4]
            ));
        }
    }
    s.push_str(&format!("    }}\n    out[wid.x * 64u + lid] = {};\n}}\n", accs.join(" + ")));
    s
}

/// The FMA ceiling (`shaders/fma_peak.wgsl`) and one 64x64 layer as a tiled product in two
/// block shapes (`shaders/tile_layer.wgsl`).
pub fn probes(gpu: &Gpu, reps: u32) -> Result<Probes, NircError> {
    const ITERATIONS: u32 = 4096;
    let invocations = 64 * 256u32;
    let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("nirc probe out"),
        size: invocations as u64 * 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let fma_src = format!(
        "const ITERATIONS: u32 = {ITERATIONS}u;\n{}",
        include_str!("../shaders/fma_peak.wgsl")
    );
    let [fma] = render::compute::pipelines_auto_layout(
        gpu,
        "fma peak",
        &render::shader::Program::single("package::bench::fma_peak", &fma_src),
        ["main"],
    )?;
    let fma_s = dispatch_timed(gpu, reps, &fma, &[(0, &out)], invocations / 64)?;
    let layer_src = format!(
        "{}\n{}\n{}",
        include_str!("../shaders/tile_layer.wgsl"),
        tile_layer_probe(4, 16),
        tile_layer_probe(16, 16)
    );
    let [block4x16, block16x16] = render::compute::pipelines_auto_layout(
        gpu,
        "tile layer",
        &render::shader::Program::single("package::bench::tile_layer", &layer_src),
        ["block4x16", "block16x16"],
    )?;
    let tiles = 256u32;
    let input = upload(gpu, "probe input", &vec![0.01f32; tiles as usize * 4096]);
    let weights = upload(gpu, "probe weights", &vec![0.02f32; 4096]);
    let layer_flops = tiles as f64 * 2.0 * 64f64.powi(3);
    let layer = |p: &wgpu::ComputePipeline| {
        dispatch_timed(gpu, reps, p, &[(0, &input), (1, &weights), (2, &out)], tiles)
            .map(|s| layer_flops / s / 1e9)
    };
    Ok(Probes {
        fma_gflops: invocations as f64 * ITERATIONS as f64 * 8.0 * 4.0 * 2.0 / fma_s / 1e9,
        layer_4x16_gflops: layer(&block4x16)?,
        layer_16x16_gflops: layer(&block16x16)?,
    })
}

/// One 64x64 layer with one record per invocation, its 64 inputs in named registers, the weights
/// read from `kind` memory ("uniform", "storage", "workgroup"); with `unroll_q` every offset is
/// a constant, else the 16 output quads are a loop (the register form's shape, methods/nirc/src/gpu/lane.rs).
/// Kind "uniform2": "uniform" with two records per invocation, each weight load feeding both.
/// GFLOP/s, and the seconds of pipeline creation plus the first dispatch (lavapipe compiles then).
pub fn register_layer_probe(
    gpu: &Gpu,
    reps: u32,
    kind: &str,
    unroll_q: bool,
) -> Result<(f64, f64), NircError> {
    let mut s = String::from(
        "@group(0) @binding(0) var<storage, read> input: array<vec4<f32>>;\n@group(0) @binding(2) var<storage, read_write> out: array<vec4<f32>>;\n",
    );
    match kind {
        "uniform" | "uniform2" => s.push_str("@group(0) @binding(1) var<uniform> w: array<vec4<f32>, 1024>;\n"),
        "storage" => s.push_str("@group(0) @binding(1) var<storage, read> w: array<vec4<f32>, 1024>;\n"),
        _ => s.push_str("@group(0) @binding(1) var<storage, read> wsrc: array<vec4<f32>, 1024>;\nvar<workgroup> w: array<vec4<f32>, 1024>;\n"),
    }
    s.push_str("@compute @workgroup_size(64)\nfn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {\n    let r = gid.x;\n");
    if kind == "workgroup" {
        s.push_str("    for (var e = lid; e < 1024u; e += 64u) { w[e] = wsrc[e]; }\n    workgroupBarrier();\n");
    }
    let pair = kind == "uniform2";
    let per = if pair { 2 } else { 1 };
    for q in 0..16 {
        s.push_str(&format!("    let v{q} = input[r * {} + {q}u];\n", 16 * per));
        if pair {
            s.push_str(&format!("    let u{q} = input[r * 32u + 16u + {q}u];\n"));
        }
    }
    let comp = ["x", "y", "z", "w"];
    s.push_str("    var total = vec4<f32>(0.0);\n");
    if pair {
        s.push_str("    var total2 = vec4<f32>(0.0);\n    for (var q = 0u; q < 16u; q++) {\n        var acc = vec4<f32>(0.0);\n        var acc2 = vec4<f32>(0.0);\n");
        for k in 0..64 {
            s.push_str(&format!("        let w{k} = w[{}u + q];\n        acc += v{}.{} * w{k};\n        acc2 += u{}.{} * w{k};\n", k * 16, k / 4, comp[k % 4], k / 4, comp[k % 4]));
        }
        s.push_str("        total += max(acc, vec4<f32>(0.0));\n        total2 += max(acc2, vec4<f32>(0.0));\n    }\n    out[2u * r + 1u] = total2;\n    out[2u * r] = total;\n}\n");
    } else if unroll_q {
        for q in 0..16 {
            s.push_str("    {\n        var acc = vec4<f32>(0.0);\n");
            for k in 0..64 {
                s.push_str(&format!(
                    "        acc += v{}.{} * w[{}u];\n",
                    k / 4,
                    comp[k % 4],
                    k * 16 + q
                ));
            }
            s.push_str("        total += max(acc, vec4<f32>(0.0));\n    }\n");
        }
    } else {
        s.push_str("    for (var q = 0u; q < 16u; q++) {\n        var acc = vec4<f32>(0.0);\n");
        for k in 0..64 {
            s.push_str(&format!(
                "        acc += v{}.{} * w[{}u + q];\n",
                k / 4,
                comp[k % 4],
                k * 16
            ));
        }
        s.push_str("        total += max(acc, vec4<f32>(0.0));\n    }\n");
    }
    if !pair {
        s.push_str("    out[r] = total;\n}\n");
    }
    let t0 = Instant::now();
    let [p] = render::compute::pipelines_auto_layout(
        gpu,
        "register layer",
        &render::shader::Program::single("package::bench::register_layer", &s),
        ["main"],
    )?;
    let records = 64 * 256u32;
    let input = upload(gpu, "probe input", &vec![0.01f32; records as usize * 64]);
    let usage = if kind.starts_with("uniform") {
        wgpu::BufferUsages::UNIFORM
    } else {
        wgpu::BufferUsages::STORAGE
    };
    let weights = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe w"),
        contents: bytemuck::cast_slice(&vec![0.02f32; 4096]),
        usage,
    });
    let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe out"),
        size: records as u64 * 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let secs = dispatch_timed(
        gpu,
        reps,
        &p,
        &[(0, &input), (1, &weights), (2, &out)],
        records / 64 / per,
    )?;
    // dispatch_timed ran one warm-up dispatch before the timed ones.
    let compile_s = t0.elapsed().as_secs_f64() - reps as f64 * secs;
    Ok((records as f64 * 2.0 * 4096.0 / secs / 1e9, compile_s))
}
