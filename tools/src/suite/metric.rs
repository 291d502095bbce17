//! The numbers a gate or a claim can judge: per-frame ones read from a run's frame records, and
//! JOD, one number per window of frames.

use std::fmt;

use serde::de::{self, EnumAccess, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use frame::frame_record::FrameRecord;
use playback::methods::registry;
use playback::methods::{Better, FolderInput, FolderStatistic, Source, Statistic};

/// A number every method has, or one a method declares (`Method`: its statistic's name, e.g.
/// `PathLength`, looked up in the registry: `playback::methods::registry::statistic`). Claims and
/// suites write either by name: `metric: Flip`, `metric: PathLength`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Metric {
    /// Mean FLIP against the reference (frames with a reference only).
    Flip,
    /// SMAPE against the previous frame: the flicker.
    Smape,
    /// SMAPE against the motion-reprojected previous frame.
    SmapeReprojected,
    Mse,
    RelMse,
    Psnr,
    /// ColorVideoVDP's JOD of the window's frames played as a video against the references (not
    /// a per-frame mean: report::jod). Higher is better; 10 = no visible difference.
    Cvvdp,
    /// The frame's time in ms: the sum of its passes' times (GPU timestamps or per-pass wall
    /// time), only when every pass was timed. A timing: it varies from run to run.
    FrameMs,
    /// Rays traced this frame (every method counts its own on the GPU).
    Rays,
    /// Paths shaded this frame.
    Shaded,
    /// The summed ms of some of a frame's passes (`reproduce::pass_ms`, the claim's statistic
    /// names them), a method's share of a cache's passes included: Table 1's tracer and
    /// propagation columns. Read from frames.csv by `flicker reproduce`, not a frame record's
    /// field, so it is not in `all`. A timing.
    PassMs,
    /// A statistic a method declares (`MethodPlugin::STATISTICS`), by its registered name.
    Method(&'static str),
}

/// The metrics every method has, with the names claims and suites write.
const COMMON: [(Metric, &str); 11] = [
    (Metric::Flip, "Flip"),
    (Metric::Smape, "Smape"),
    (Metric::SmapeReprojected, "SmapeReprojected"),
    (Metric::Mse, "Mse"),
    (Metric::RelMse, "RelMse"),
    (Metric::Psnr, "Psnr"),
    (Metric::Cvvdp, "Cvvdp"),
    (Metric::FrameMs, "FrameMs"),
    (Metric::Rays, "Rays"),
    (Metric::Shaded, "Shaded"),
    (Metric::PassMs, "PassMs"),
];

impl Metric {
    /// The metric a claim or a suite calls `name`: a common one, or a registered method's
    /// statistic.
    pub fn named(name: &str) -> Option<Metric> {
        COMMON
            .iter()
            .find(|(_, n)| *n == name)
            .map(|(m, _)| *m)
            .or_else(|| registry::statistic(name).map(|(_, s)| Metric::Method(s.name)))
    }

    /// Every per-frame metric a frame record holds, which suites' runs, sweeps and baselines
    /// keep: the common ones and the registered methods' frames.csv statistics.
    pub fn all() -> Vec<Metric> {
        let common = [
            Metric::Flip,
            Metric::Cvvdp,
            Metric::Smape,
            Metric::SmapeReprojected,
            Metric::Mse,
            Metric::RelMse,
            Metric::Psnr,
            Metric::FrameMs,
            Metric::Rays,
            Metric::Shaded,
        ];
        let of_methods = registry::statistics()
            .into_iter()
            .filter(|s| s.source == Source::Frames)
            .map(|s| Metric::Method(s.name));
        common.into_iter().chain(of_methods).collect()
    }

    /// The method's declaration of a `Method` metric.
    pub fn statistic(self) -> Option<&'static Statistic> {
        match self {
            Metric::Method(name) => registry::statistic(name).map(|(_, s)| s),
            _ => None,
        }
    }

    /// How `flicker reproduce` computes it from a run's images, where it does (the method's
    /// computation, run through `reproduce::folder_statistic`).
    pub fn from_images_by(self) -> Option<FolderStatistic> {
        match self.statistic()?.source {
            Source::Images(how) => Some(how),
            _ => None,
        }
    }

    /// The name claims and suites write: `Flip`, `PathLength`.
    pub fn ident(self) -> &'static str {
        match self {
            Metric::Method(name) => name,
            m => COMMON.iter().find(|(c, _)| *c == m).map(|(_, n)| *n).expect("listed"),
        }
    }

    /// Its key: the series' name in runs, baselines and tables, a method statistic's frames.csv
    /// column (`flip`, `path_length`).
    pub fn name(self) -> &'static str {
        match self {
            Metric::Flip => "flip",
            Metric::Smape => "smape",
            Metric::SmapeReprojected => "smape_reprojected",
            Metric::Mse => "mse",
            Metric::RelMse => "rel_mse",
            Metric::Psnr => "psnr",
            Metric::Cvvdp => "jod",
            Metric::FrameMs => "frame_ms",
            Metric::Rays => "rays",
            Metric::Shaded => "shaded",
            Metric::PassMs => "pass_ms",
            Metric::Method(name) => self.statistic().map_or(name, |s| s.column),
        }
    }

    /// Errors get worse upwards, PSNR and JOD downwards; a method's statistic says.
    pub fn higher_is_better(self) -> bool {
        match self {
            Metric::Psnr | Metric::Cvvdp => true,
            m => m.statistic().is_some_and(|s| s.better == Better::Higher),
        }
    }

    /// Computed from a run's images against another method's (the claim's `against`, e.g.
    /// SSS's PSNR), not read from frame records.
    pub fn from_images(self) -> bool {
        self.from_images_by().is_some_and(|i| i.input == FolderInput::Against)
    }

    /// Read back from a run's frames.csv or images by `flicker reproduce` only (not kept in a
    /// suite's runs or baselines): a suite gate cannot judge it.
    pub fn reproduce_only(self) -> bool {
        self == Metric::PassMs
            || self.statistic().is_some_and(|s| match s.source {
                Source::FramesReproduceOnly => true,
                Source::Images(i) => i.input == FolderInput::WholeRun,
                Source::Frames => false,
            })
    }

    /// Whether the metric is a per-frame number (its window value is a mean of frames); JOD is
    /// one number per window.
    pub fn per_frame(self) -> bool {
        self != Metric::Cvvdp
    }

    /// A measured time: not reproducible run to run, so two runs agree on it only within noise.
    pub fn is_timing(self) -> bool {
        matches!(self, Metric::FrameMs | Metric::PassMs)
    }

    /// Whether a method of plugin kind `kind` (`MethodPlugin::NAME`) records this metric in a
    /// run whose scenario has reference frames (`references`): the image metrics every method
    /// has (against a reference only where there is one), a statistic only the method that
    /// declares it.
    pub fn recorded_by(self, kind: &str, references: bool) -> bool {
        match self {
            Metric::Smape | Metric::SmapeReprojected => true,
            Metric::FrameMs | Metric::PassMs | Metric::Rays | Metric::Shaded => true,
            Metric::Flip | Metric::Mse | Metric::RelMse | Metric::Psnr | Metric::Cvvdp => {
                references
            }
            Metric::Method(name) => registry::statistic(name).is_some_and(|(method, s)| {
                method.name() == kind && (references || !s.needs_references)
            }),
        }
    }

    pub fn of(self, r: &FrameRecord) -> Option<f64> {
        match self {
            Metric::Flip => r.flip,
            Metric::Smape => r.smape,
            Metric::SmapeReprojected => r.smape_reprojected,
            Metric::Mse => r.mse,
            Metric::RelMse => r.rel_mse,
            Metric::Psnr => r.psnr,
            Metric::Cvvdp | Metric::PassMs => None,
            Metric::FrameMs => r.passes_total_ms(),
            Metric::Rays => r.rays.map(|n| n as f64),
            Metric::Shaded => r.shaded.map(|n| n as f64),
            // A method's statistic, by the column the method reports it under.
            Metric::Method(_) => {
                let s = self.statistic().filter(|s| !matches!(s.source, Source::Images(_)))?;
                r.stats.iter().find(|(n, _)| n == s.column).map(|s| s.1)
            }
        }
    }
}

/// Written as its name: `Flip`, `PathLength`.
impl Serialize for Metric {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_unit_variant("Metric", 0, self.ident())
    }
}

/// Read as a unit variant (`metric: Flip`, `metric: PathLength`): a common metric's name or a
/// registered method's statistic's.
impl<'de> Deserialize<'de> for Metric {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MetricVisitor;
        impl<'de> Visitor<'de> for MetricVisitor {
            type Value = Metric;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a metric, e.g. Flip or a method's statistic such as PathLength")
            }
            fn visit_str<E: de::Error>(self, name: &str) -> Result<Metric, E> {
                Metric::named(name).ok_or_else(|| {
                    let known: Vec<&str> = COMMON
                        .iter()
                        .map(|(_, n)| *n)
                        .chain(registry::statistics().iter().map(|s| s.name))
                        .collect();
                    E::custom(format!(
                        "unknown metric `{name}`, expected one of {}",
                        known.join(", ")
                    ))
                })
            }
            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Metric, A::Error> {
                let (Ident(name), variant) = data.variant()?;
                variant.unit_variant()?;
                self.visit_str(&name)
            }
        }
        /// The variant's name, read as an identifier (a `String` would want a quoted string).
        struct Ident(String);
        impl<'de> Deserialize<'de> for Ident {
            fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                struct IdentVisitor;
                impl Visitor<'_> for IdentVisitor {
                    type Value = Ident;
                    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                        f.write_str("a metric's name")
                    }
                    fn visit_str<E: de::Error>(self, name: &str) -> Result<Ident, E> {
                        Ok(Ident(name.to_string()))
                    }
                }
                deserializer.deserialize_identifier(IdentVisitor)
            }
        }
        deserializer.deserialize_enum("Metric", &[], MetricVisitor)
    }
}

impl Metric {
    /// A method statistic known to be registered (tools' own code naming a shipped one).
    pub fn shipped(name: &str) -> Metric {
        match Metric::named(name) {
            Some(m) => m,
            None => panic!("no registered method declares the statistic {name}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> FrameRecord {
        FrameRecord {
            method: "m".into(),
            frame: 0,
            cpu_ms: 50.0,
            passes: vec![("trace".into(), Some(2.5)), ("shade".into(), Some(1.25))],
            clock: None,
            rays: Some(1200),
            shaded: Some(576),
            smape: None,
            smape_reprojected: None,
            disoccluded: None,
            flip: None,
            mse: None,
            rel_mse: None,
            psnr: None,
            regions: vec![],
            stats: vec![
                ("sss_mean_spp".into(), 17.5),
                ("primary_rays".into(), 300.0),
                ("blend_sigma".into(), 0.25),
                ("mean_std".into(), 0.01),
                ("rms_bias".into(), 0.02),
            ],
        }
    }

    #[test]
    fn counts_times_and_stats_are_read_from_the_record() {
        let r = record();
        // The frame time is the passes' sum, not the CPU time.
        assert_eq!(Metric::FrameMs.of(&r), Some(3.75));
        assert_eq!(Metric::Rays.of(&r), Some(1200.0));
        assert_eq!(Metric::Shaded.of(&r), Some(576.0));
        assert_eq!(Metric::shipped("SssSpp").of(&r), Some(17.5));
        assert_eq!(Metric::shipped("PrimaryRays").of(&r), Some(300.0));
        assert_eq!(Metric::shipped("BlendSigma").of(&r), Some(0.25));
        assert_eq!(Metric::shipped("MeanStd").of(&r), Some(0.01));
        assert_eq!(Metric::shipped("RmsBias").of(&r), Some(0.02));
        // A stat the method does not report is missing, not 0.
        assert_eq!(Metric::shipped("PathLength").of(&r), None);
        // One untimed pass: the frame has no time (a partial sum would look faster).
        let mut untimed = record();
        untimed.passes[1].1 = None;
        assert_eq!(Metric::FrameMs.of(&untimed), None);
        let mut no_passes = record();
        no_passes.passes.clear();
        assert_eq!(Metric::FrameMs.of(&no_passes), None);
        // Names are distinct (they key baselines and run columns).
        let mut names: Vec<&str> = Metric::all().iter().map(|m| m.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Metric::all().len());
    }

    #[test]
    fn stats_are_recorded_only_by_their_method() {
        assert!(Metric::shipped("SssSpp").recorded_by("Sss", false));
        assert!(!Metric::shipped("SssSpp").recorded_by("PathTracing", true));
        assert!(Metric::shipped("BlendSigma").recorded_by("Nirc", true));
        assert!(Metric::shipped("PrimaryRays").recorded_by("SampleCache", true));
        assert!(!Metric::shipped("PrimaryRays").recorded_by("HashCache", true));
        assert!(Metric::shipped("RmsBias").recorded_by("VolumeTransmittance", false));
        assert!(!Metric::shipped("RmsBias").recorded_by("VolumePath", true));
        assert!(Metric::FrameMs.recorded_by("PathTracing", false));
        assert!(Metric::FrameMs.is_timing() && !Metric::Rays.is_timing());
    }

    #[test]
    fn names_are_read_and_written_as_claims_write_them() {
        let read = |text: &str| ron::from_str::<Metric>(text);
        assert_eq!(read("Flip").unwrap(), Metric::Flip);
        assert_eq!(read("PathLength").unwrap(), Metric::Method("PathLength"));
        assert_eq!(Metric::shipped("PathLength").name(), "path_length");
        assert_eq!(Metric::shipped("SssSpp").name(), "sss_mean_spp");
        assert_eq!(ron::to_string(&Metric::shipped("SssPsnr")).unwrap(), "SssPsnr");
        let e = read("PathLenght").unwrap_err().to_string();
        assert!(e.contains("unknown metric `PathLenght`") && e.contains("PathLength"), "{e}");
        // What a method's declaration says, read through the metric.
        assert!(Metric::shipped("SssPsnr").higher_is_better() && Metric::Psnr.higher_is_better());
        assert!(!Metric::shipped("BlendSigma").higher_is_better());
        assert!(Metric::shipped("SssPsnr").from_images() && !Metric::Flip.from_images());
        assert!(Metric::shipped("CacheMean").reproduce_only());
        assert!(Metric::shipped("VarianceOverBound").reproduce_only());
        assert!(!Metric::shipped("PathLength").reproduce_only());
        assert!(!Metric::all().contains(&Metric::shipped("CacheMean")));
        assert!(Metric::all().contains(&Metric::shipped("PathLength")));
        assert!(Metric::shipped("SigmaChanged").recorded_by("Nirc", true));
        assert!(!Metric::shipped("SigmaChanged").recorded_by("Nirc", false));
    }
}
