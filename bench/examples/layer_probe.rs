//! Where the register form came from (methods/nirc/src/gpu/lane.rs): one 64x64 layer with one record per
//! invocation and its inputs in registers, the weights read at constant or loop-uniform offsets
//! from uniform, storage or workgroup memory, against the tiled probes; then the tiled and the
//! register-form inference side by side in one process.
//! `cargo run -p bench --example layer_probe [variants|forms]` (the storage-unrolled variant
//! takes minutes to compile on lavapipe).
use nirc::gpu::shaders::WeightPlacement;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let what = std::env::args().nth(1).unwrap_or_default();
    let gpu = render::gpu::Gpu::new()?;
    if what != "forms" {
        let p = bench::nirc_throughput::probes(&gpu, 3)?;
        println!(
            "FMA ceiling {:.1} GFLOP/s; tiled 4x16 {:.2}, 16x16 {:.2}",
            p.fma_gflops, p.layer_4x16_gflops, p.layer_16x16_gflops
        );
        for kind in ["uniform", "uniform2", "storage", "workgroup"] {
            for unroll in [true, false] {
                if kind == "uniform2" && unroll {
                    continue; // two records per invocation exist in the loop shape only
                }
                let (gflops, compile_s) =
                    bench::nirc_throughput::register_layer_probe(&gpu, 3, kind, unroll)?;
                let memory =
                    if kind == "uniform2" { "uniform, two records per invocation" } else { kind };
                println!(
                    "weights in {memory}, output quads {}: {gflops:.2} GFLOP/s (pipeline and first dispatch {compile_s:.1} s)",
                    if unroll { "unrolled" } else { "in a loop" }
                );
            }
        }
    }
    if what != "variants" {
        let config = nirc::NircCacheSettings::default();
        for placement in [WeightPlacement::Tiled, WeightPlacement::Registers] {
            let r = bench::nirc_throughput::run(&gpu, &config, Some(placement), 4096, 16384, 3)?;
            println!(
                "{placement:?}: EMA-only {:.0} queries/s ({:.2} GFLOP/s), blend {:.0} queries/s, blend overhead {:.1}% of the bench's step + inference, {:.1}% of EMA-only inference",
                r.ema_only_queries_per_s,
                r.infer_gflops,
                r.blend_queries_per_s,
                r.blend_overhead_step_percent,
                r.blend_overhead_infer_percent
            );
        }
    }
    Ok(())
}
