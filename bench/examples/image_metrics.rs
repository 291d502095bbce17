//! `cargo run --release -p bench --example image_metrics -- [--width 1280 --height 720 --repeats 5]`:
//! SMAPE and HDR-FLIP timings, and NVIDIA's FLIP on the same pair.

use clap::Parser;

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    bench: bench::image_metrics::BenchArgs,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let report = bench::image_metrics::bench(&cli.bench)?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
