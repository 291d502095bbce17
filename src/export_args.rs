//! `flicker export`'s command line, read into [`tools::export::ExportOptions`].

use std::path::PathBuf;

/// `flicker export SCENARIO --out DIR [--frames N] [--resolution WxH] [--seed S]
/// [--reference-spp N] [--scene-only]`.
#[derive(Clone, Debug, clap::Args)]
pub struct ExportArgs {
    /// The scenario file (RON), e.g. scenarios/showcase.ron
    pub scenario: PathBuf,
    /// The package folder to write (an earlier package there is replaced; any other non-empty
    /// folder is refused).
    #[arg(long)]
    pub out: PathBuf,
    /// Number of recorded frames (overrides the scenario).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Image size as WIDTHxHEIGHT (overrides the scenario).
    #[arg(long, value_parser = crate::parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Random seed (overrides the scenario).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Samples per pixel of the references [default: the scenario's reference spp].
    #[arg(long)]
    pub reference_spp: Option<u32>,
    /// Write the glTF, the frame records and the manifest only: no references, no inputs.
    #[arg(long)]
    pub scene_only: bool,
    /// Cache folder for references [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Do not draw the progress bar.
    #[arg(long)]
    pub quiet: bool,
}

impl ExportArgs {
    pub fn options(self) -> tools::export::ExportOptions {
        tools::export::ExportOptions {
            scenario: self.scenario,
            out: self.out,
            overrides: playback::play::Overrides {
                frames: self.frames,
                resolution: self.resolution,
                seed: self.seed,
                ..Default::default()
            },
            reference_spp: self.reference_spp,
            cache_dir: self.cache_dir,
            progress: !self.quiet,
            scene_only: self.scene_only,
        }
    }
}
