//! `flicker measure`'s command line, read into [`tools::measure::MeasureOptions`].

use std::path::PathBuf;

/// `flicker measure --reference DIR --test NAME=DIR [--test NAME=DIR ...] [--motion NAME=DIR]
/// [--fps N] [--events FRAME,...] [--out RUN]`.
#[derive(Clone, Debug, clap::Args)]
pub struct MeasureArgs {
    /// The reference frames: a folder of EXR or PNG files numbered by frame (e.g. 0007.exr).
    #[arg(long)]
    pub reference: PathBuf,
    /// A test sequence as NAME=DIR (frames numbered like the reference's); repeat for more.
    #[arg(long = "test", value_parser = parse_named, required = true)]
    pub tests: Vec<(String, PathBuf)>,
    /// Motion vectors of a test as NAME=DIR (EXR; R, G: pixels from a frame to the previous),
    /// for reprojected SMAPE.
    #[arg(long = "motion", value_parser = parse_named)]
    pub motion: Vec<(String, PathBuf)>,
    /// Frames per second of the sequences (JOD's temporal channels depend on it).
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Frames where something happens (the input's frame numbers), e.g. 10,40: the summary's
    /// windows before and after each.
    #[arg(long, value_delimiter = ',')]
    pub events: Vec<u32>,
    /// The run folder to write.
    #[arg(long, default_value = "runs/measure")]
    pub out: PathBuf,
    /// The display JOD is judged on (a display model of ColorVideoVDP).
    #[arg(long, default_value = metrics::cvvdp::DEFAULT_DISPLAY)]
    pub display: String,
    /// Radiance times this is the display's white.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// ε in SMAPE's denominator.
    #[arg(long, default_value_t = 0.01)]
    pub smape_epsilon: f32,
}

fn parse_named(s: &str) -> Result<(String, PathBuf), String> {
    let (name, dir) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=DIR such as taa=frames/taa, got '{s}'"))?;
    if name.is_empty() || dir.is_empty() {
        return Err(format!("expected NAME=DIR such as taa=frames/taa, got '{s}'"));
    }
    Ok((name.to_string(), PathBuf::from(dir)))
}

impl MeasureArgs {
    pub fn options(self) -> tools::measure::MeasureOptions {
        tools::measure::MeasureOptions {
            reference: self.reference,
            tests: self.tests,
            motion: self.motion,
            fps: self.fps,
            events: self.events,
            out: self.out,
            cvvdp: metrics::CvvdpSettings {
                display: self.display,
                exposure: self.exposure,
                enabled: true,
            },
            smape_epsilon: self.smape_epsilon,
        }
    }
}
