//! Throughput of the GPU cache at width 64 on this adapter, every MLP form:
//! `cargo run --release -p bench --example nirc_bench [batch] [queries] [reps]`
//! (`flicker bench --nirc` runs the default form and writes JSON). With `FLICKER_NIRC_MLP` set,
//! only that form runs.

use nirc::NircCacheSettings;
use nirc::gpu::shaders::WeightPlacement;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<u32> =
        std::env::args().skip(1).map(|a| a.parse().expect("numbers: batch queries reps")).collect();
    let batch = args.first().copied().unwrap_or(4096);
    let queries = args.get(1).copied().unwrap_or(16384);
    let reps = args.get(2).copied().unwrap_or(3);
    let gpu = render::gpu::Gpu::new()?;
    let config = NircCacheSettings::default();
    let forms = match WeightPlacement::from_env()? {
        Some(one) => vec![one],
        None => vec![WeightPlacement::Registers, WeightPlacement::Tiled, WeightPlacement::Storage],
    };
    for placement in forms {
        let r = bench::nirc_throughput::run(&gpu, &config, Some(placement), batch, queries, reps)?;
        println!("{}", serde_json::to_string_pretty(&r)?);
    }
    Ok(())
}
