//! The numbers a gate or a claim can judge: per-frame ones read from a run's frame records, and
//! JOD, one number per window of frames.

use serde::{Deserialize, Serialize};

use systems::frame_record::FrameRecord;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
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
    /// Mean path length in vertices (the termination method's `path_length` stat). Shorter is
    /// "better": `Better(than: M)` on it says the method's paths are shorter than M's.
    PathLength,
    /// Mean |bias| of the transmittance image against the exact one (the VolumeTransmittance
    /// method's `mean_abs_bias` stat).
    MeanAbsBias,
    /// Mean per-pixel standard deviation of the transmittance estimate (VolumeTransmittance's
    /// `mean_std` stat).
    MeanStd,
    /// RMS over pixels of the noise-corrected bias of the transmittance image against the
    /// exact one (VolumeTransmittance's `rms_bias` stat, `media::image::rms_bias`): the bias
    /// the jackknife paper reads from 2^18 spp, without the noise of a few dozen estimates.
    RmsBias,
    /// The frame's time in ms: the sum of its passes' times (GPU timestamps or per-pass wall
    /// time), only when every pass was timed. A timing: it varies from run to run.
    FrameMs,
    /// Rays traced this frame (every method counts its own on the GPU).
    Rays,
    /// Paths shaded this frame.
    Shaded,
    /// Mean samples per SSS pixel (the Sss method's `sss_mean_spp` stat).
    SssSpp,
    /// Primary rays the sample cache traced this frame (SampleCache's `primary_rays` stat).
    PrimaryRays,
    /// Mean blend weight σ of the High-LR side over the image (Nirc's `blend_sigma` stat).
    BlendSigma,
    /// PSNR (dB) of luminance over the SSS pixels against another method's frames of the same
    /// run (realtime-sss-thesis Table 7.3 against its converged pass). Not a frames.csv column:
    /// `flicker reproduce` computes it from the run folder's images (`from_images`), so it is
    /// not in `ALL` and no suite gate reads it.
    SssPsnr,
    /// The summed ms of some of a frame's passes (`reproduce::pass_ms`, the claim's statistic
    /// names them), a method's share of a cache's passes included: Table 1's tracer and
    /// propagation columns. Read from frames.csv by `flicker reproduce`, not a frame record's
    /// field, so it is not in `ALL`. A timing.
    PassMs,
    /// A NIRC blend's mean σ over the fifth of the pixels whose reference changed most across
    /// the case's first event, and over the fifth that changed least (`reproduce::sigma_regions`,
    /// from the preference maps and references in the run folder; not in `ALL`).
    SigmaChanged,
    SigmaUnchanged,
    /// The termination cache's mean luminance E[Y] over its filled records (frames.csv's
    /// `cache_mean`), and below their mean variance and squared bias: how the cache follows a
    /// change of lighting. Read back from frames.csv by `flicker reproduce`
    /// (`reproduce::frame_columns`), not in `ALL`, so sweeps and baselines keep their columns.
    CacheMean,
    /// `cache_variance`: the mean of E[Y²] − E[E[Y|y]²] over the filled records.
    CacheVariance,
    /// `cache_bias2`: the mean of E[E[Y|y]²] − E[Y]² over the filled records.
    CacheBias2,
    /// variance-trading-termination's Fig. 7: the image variance over its bound. Per frame, the
    /// mean over pixels of the squared deviation of the frame's luminance from the pixel's mean
    /// over the run's frames, times n/(n − 1), divided by the method's absolute threshold
    /// t · unit² (frames.csv's `variance_bound_log10`): over all the frames of a static scene's run
    /// (window Overall) the mean is the estimator's per-pixel variance over the bound
    /// (`reproduce::variance_bound`, from the run's images; not in `ALL`).
    VarianceOverBound,
}

impl Metric {
    pub const ALL: [Metric; 17] = [
        Metric::Flip,
        Metric::Cvvdp,
        Metric::Smape,
        Metric::SmapeReprojected,
        Metric::Mse,
        Metric::RelMse,
        Metric::Psnr,
        Metric::PathLength,
        Metric::MeanAbsBias,
        Metric::MeanStd,
        Metric::RmsBias,
        Metric::FrameMs,
        Metric::Rays,
        Metric::Shaded,
        Metric::SssSpp,
        Metric::PrimaryRays,
        Metric::BlendSigma,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Metric::Flip => "flip",
            Metric::Smape => "smape",
            Metric::SmapeReprojected => "smape_reprojected",
            Metric::Mse => "mse",
            Metric::RelMse => "rel_mse",
            Metric::Psnr => "psnr",
            Metric::Cvvdp => "jod",
            Metric::PathLength => "path_length",
            Metric::MeanAbsBias => "mean_abs_bias",
            Metric::MeanStd => "mean_std",
            Metric::RmsBias => "rms_bias",
            Metric::FrameMs => "frame_ms",
            Metric::Rays => "rays",
            Metric::Shaded => "shaded",
            Metric::SssSpp => "sss_mean_spp",
            Metric::PrimaryRays => "primary_rays",
            Metric::BlendSigma => "blend_sigma",
            Metric::SssPsnr => "sss_psnr",
            Metric::PassMs => "pass_ms",
            Metric::SigmaChanged => "sigma_changed",
            Metric::SigmaUnchanged => "sigma_unchanged",
            Metric::CacheMean => "cache_mean",
            Metric::CacheVariance => "cache_variance",
            Metric::CacheBias2 => "cache_bias2",
            Metric::VarianceOverBound => "variance_over_bound",
        }
    }

    /// Errors get worse upwards, PSNR and JOD downwards.
    pub fn higher_is_better(self) -> bool {
        matches!(self, Metric::Psnr | Metric::Cvvdp | Metric::SssPsnr)
    }

    /// Computed from a run's images against another method's (`reproduce::sss_psnr`), not read
    /// from frame records.
    pub fn from_images(self) -> bool {
        self == Metric::SssPsnr
    }

    /// Read back from a run's frames.csv by `flicker reproduce` only (not kept in a suite's
    /// runs or baselines): a suite gate cannot judge it.
    pub fn reproduce_only(self) -> bool {
        matches!(
            self,
            Metric::PassMs
                | Metric::CacheMean
                | Metric::CacheVariance
                | Metric::CacheBias2
                | Metric::VarianceOverBound
        )
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
    /// has (against a reference only where there is one), the stats only their method.
    pub fn recorded_by(self, kind: &str, references: bool) -> bool {
        match self {
            Metric::Smape | Metric::SmapeReprojected => true,
            Metric::FrameMs | Metric::PassMs | Metric::Rays | Metric::Shaded => true,
            Metric::Flip | Metric::Mse | Metric::RelMse | Metric::Psnr | Metric::Cvvdp => {
                references
            }
            Metric::PathLength
            | Metric::CacheMean
            | Metric::CacheVariance
            | Metric::CacheBias2
            | Metric::VarianceOverBound => kind == "Termination",
            Metric::MeanAbsBias | Metric::MeanStd | Metric::RmsBias => {
                kind == "VolumeTransmittance"
            }
            Metric::SssSpp => kind == "Sss",
            Metric::PrimaryRays => kind == "SampleCache",
            Metric::BlendSigma => kind == "Nirc",
            Metric::SssPsnr => kind == "Sss",
            Metric::SigmaChanged | Metric::SigmaUnchanged => kind == "Nirc" && references,
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
            Metric::Cvvdp | Metric::SssPsnr | Metric::PassMs | Metric::VarianceOverBound => None,
            Metric::SigmaChanged | Metric::SigmaUnchanged => None,
            Metric::FrameMs => r.passes_total_ms(),
            Metric::Rays => r.rays.map(|n| n as f64),
            Metric::Shaded => r.shaded.map(|n| n as f64),
            // Method stats, by the name the method reports them under.
            Metric::PathLength
            | Metric::MeanAbsBias
            | Metric::MeanStd
            | Metric::RmsBias
            | Metric::SssSpp
            | Metric::PrimaryRays
            | Metric::BlendSigma
            | Metric::CacheMean
            | Metric::CacheVariance
            | Metric::CacheBias2 => r.stats.iter().find(|(n, _)| n == self.name()).map(|s| s.1),
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
        assert_eq!(Metric::SssSpp.of(&r), Some(17.5));
        assert_eq!(Metric::PrimaryRays.of(&r), Some(300.0));
        assert_eq!(Metric::BlendSigma.of(&r), Some(0.25));
        assert_eq!(Metric::MeanStd.of(&r), Some(0.01));
        assert_eq!(Metric::RmsBias.of(&r), Some(0.02));
        // A stat the method does not report is missing, not 0.
        assert_eq!(Metric::PathLength.of(&r), None);
        // One untimed pass: the frame has no time (a partial sum would look faster).
        let mut untimed = record();
        untimed.passes[1].1 = None;
        assert_eq!(Metric::FrameMs.of(&untimed), None);
        let mut no_passes = record();
        no_passes.passes.clear();
        assert_eq!(Metric::FrameMs.of(&no_passes), None);
        // Names are distinct (they key baselines and run columns).
        let mut names: Vec<&str> = Metric::ALL.iter().map(|m| m.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Metric::ALL.len());
    }

    #[test]
    fn stats_are_recorded_only_by_their_method() {
        assert!(Metric::SssSpp.recorded_by("Sss", false));
        assert!(!Metric::SssSpp.recorded_by("PathTracing", true));
        assert!(Metric::BlendSigma.recorded_by("Nirc", true));
        assert!(Metric::PrimaryRays.recorded_by("SampleCache", true));
        assert!(!Metric::PrimaryRays.recorded_by("HashCache", true));
        assert!(Metric::RmsBias.recorded_by("VolumeTransmittance", false));
        assert!(!Metric::RmsBias.recorded_by("VolumePath", true));
        assert!(Metric::FrameMs.recorded_by("PathTracing", false));
        assert!(Metric::FrameMs.is_timing() && !Metric::Rays.is_timing());
    }
}
