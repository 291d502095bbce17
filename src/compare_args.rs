//! `flicker compare`'s command line, read into [`metrics::CompareOptions`].

use std::path::PathBuf;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use metrics::compare::FlipMode;

#[derive(Clone, Debug, clap::Args)]
pub struct CompareArgs {
    /// Reference image (.png = sRGB, .exr = linear).
    pub reference: PathBuf,
    /// Test image, same size as the reference.
    pub test: PathBuf,
    /// LDR-FLIP or HDR-FLIP; default: hdr for EXR references, ldr for PNG.
    #[arg(long, value_parser = PossibleValuesParser::new(FlipMode::NAMES)
        .try_map(|s| s.parse::<FlipMode>()))]
    pub mode: Option<FlipMode>,
    /// Pixels per degree of the viewing setup (default: 0.7 m from a 0.7 m wide 3840 px monitor).
    #[arg(long, default_value_t = metrics::DEFAULT_PPD)]
    pub ppd: f32,
    /// Write the FLIP error map here as a magma PNG.
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// ε of SMAPE's denominator.
    #[arg(long, default_value_t = metrics::smape::DEFAULT_EPS)]
    pub eps: f32,
}

impl CompareArgs {
    pub fn options(self) -> metrics::CompareOptions {
        metrics::CompareOptions {
            reference: self.reference,
            test: self.test,
            mode: self.mode,
            ppd: self.ppd,
            map: self.map,
            json: self.json,
            eps: self.eps,
        }
    }
}
