//! `flicker measure`'s command line, read into [`tools::measure::MeasureOptions`].

use std::path::PathBuf;

/// `flicker measure (--reference DIR | --scenario PACKAGE) --test NAME=DIR [--test NAME=DIR ...]
/// [--motion NAME=DIR] [--fps N] [--events FRAME,...] [--out RUN]`.
#[derive(Clone, Debug, clap::Args)]
pub struct MeasureArgs {
    /// The reference frames: a folder of EXR or PNG files numbered by frame (e.g. 0007.exr).
    #[arg(long, required_unless_present = "scenario", conflicts_with = "scenario")]
    pub reference: Option<PathBuf>,
    /// A package written by `flicker export`: its references, frame rate, events, display and
    /// SMAPE ε (each unless given here).
    #[arg(long, value_name = "PACKAGE")]
    pub scenario: Option<PathBuf>,
    /// A test sequence as NAME=DIR (frames numbered like the reference's); repeat for more.
    #[arg(long = "test", value_parser = parse_named, required = true)]
    pub tests: Vec<(String, PathBuf)>,
    /// Motion vectors of a test as NAME=DIR (EXR; R, G: pixels from a frame to the previous),
    /// for reprojected SMAPE.
    #[arg(long = "motion", value_parser = parse_named)]
    pub motion: Vec<(String, PathBuf)>,
    /// A test's per-frame times as NAME=FILE: a CSV with the header `frame,ms` (optionally more
    /// columns, one per pass) and a row per frame in milliseconds; the test joins the
    /// speed-against-accuracy charts.
    #[arg(long = "timings", value_parser = parse_named)]
    pub timings: Vec<(String, PathBuf)>,
    /// Frames per second of the sequences (JOD's temporal channels depend on it) [default: the
    /// package's, else 30].
    #[arg(long)]
    pub fps: Option<f64>,
    /// Frames where something happens (the input's frame numbers), e.g. 10,40: the summary's
    /// windows before and after each.
    #[arg(long, value_delimiter = ',')]
    pub events: Vec<u32>,
    /// The run folder to write.
    #[arg(long, default_value = "runs/measure")]
    pub out: PathBuf,
    /// The display JOD is judged on (a display model of ColorVideoVDP) [default: the package's,
    /// else standard_4k].
    #[arg(long)]
    pub display: Option<String>,
    /// Radiance times this is the display's white [default: the package's, else 1].
    #[arg(long)]
    pub exposure: Option<f32>,
    /// ε in SMAPE's denominator [default: the package's, else 0.01].
    #[arg(long)]
    pub smape_epsilon: Option<f32>,
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
    pub fn options(self) -> anyhow::Result<tools::measure::MeasureOptions> {
        let package = self.scenario.as_deref().map(tools::export::Package::read).transpose()?;
        let p = package.as_ref();
        let default = metrics::CvvdpSettings::default();
        let (events, labels) = match p {
            Some(p) if self.events.is_empty() => {
                p.events.iter().map(|(f, l)| (*f, l.clone())).unzip()
            }
            _ => (self.events, Vec::new()),
        };
        Ok(tools::measure::MeasureOptions {
            reference: p
                .map_or_else(|| self.reference.unwrap_or_default(), |p| p.reference.clone()),
            tests: self.tests,
            motion: self.motion,
            timings: self.timings,
            fps: self.fps.or(p.map(|p| p.fps)).unwrap_or(30.0),
            events,
            labels,
            out: self.out,
            cvvdp: metrics::CvvdpSettings {
                display: self
                    .display
                    .or(p.map(|p| p.cvvdp.display.clone()))
                    .unwrap_or_else(|| metrics::cvvdp::DEFAULT_DISPLAY.into()),
                exposure: self.exposure.or(p.map(|p| p.cvvdp.exposure)).unwrap_or(default.exposure),
                enabled: true,
            },
            smape_epsilon: self.smape_epsilon.or(p.map(|p| p.smape_epsilon)).unwrap_or(0.01),
        })
    }
}
