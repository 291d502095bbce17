//! `flicker`: play scenarios of dynamic scenes, measure how light-transport caches behave.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use systems::playback::{self, Overrides, RunOptions};

#[derive(Parser)]
#[command(name = "flicker", version, about = "A lab for the temporal stability of real-time light transport")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Play a scenario: render every frame of every method, the references, timings and metrics.
    Run {
        /// The scenario file (RON), e.g. scenarios/cornell_box.ron
        scenario: PathBuf,
        /// Number of recorded frames (overrides the scenario).
        #[arg(long)]
        frames: Option<u32>,
        /// Image size as WIDTHxHEIGHT, e.g. 160x90 (overrides the scenario).
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        /// Samples per pixel of every method (overrides the scenario).
        #[arg(long)]
        spp: Option<u32>,
        /// Random seed (overrides the scenario).
        #[arg(long)]
        seed: Option<u64>,
        /// Output folder (overrides the scenario).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Folder of the reference cache [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
        #[arg(long)]
        cache_dir: Option<PathBuf>,
        /// Do not draw the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// List the built-in scenes.
    Scenes,
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT such as 160x90, got '{s}'"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("expected WIDTHxHEIGHT such as 160x90, got '{s}'"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 {
        return Err(format!("width and height must be at least 1, got '{s}'"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { scenario, frames, resolution, spp, seed, out, cache_dir, quiet } => {
            let opts = RunOptions {
                scenario,
                overrides: Overrides { frames, resolution, spp, seed, out },
                cache_dir,
                progress: !quiet,
            };
            playback::run(&opts).map(|summary| {
                println!(
                    "wrote {} ({} frames; references: {} rendered, {} from cache)",
                    summary.folder.display(),
                    summary.records.len(),
                    summary.references_rendered,
                    summary.references_cached
                );
            })
        }
        Command::Scenes => {
            for (name, description) in sim::scenes::list() {
                println!("{name:<16} {description}");
            }
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
