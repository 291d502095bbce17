//! The per-frame numbers a gate can judge, read from a run's frame records.

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
}

impl Metric {
    pub const ALL: [Metric; 9] = [
        Metric::Flip,
        Metric::Cvvdp,
        Metric::Smape,
        Metric::SmapeReprojected,
        Metric::Mse,
        Metric::RelMse,
        Metric::Psnr,
        Metric::PathLength,
        Metric::MeanAbsBias,
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
        }
    }

    /// Errors get worse upwards, PSNR and JOD downwards.
    pub fn higher_is_better(self) -> bool {
        matches!(self, Metric::Psnr | Metric::Cvvdp)
    }

    /// Whether the metric is a per-frame number (its window value is a mean of frames); JOD is
    /// one number per window.
    pub fn per_frame(self) -> bool {
        self != Metric::Cvvdp
    }

    /// Whether a method of plugin kind `kind` (`MethodPlugin::NAME`) records this metric in a
    /// run whose scenario has reference frames (`references`): the image metrics every method
    /// has (against a reference only where there is one), the stats only their method.
    pub fn recorded_by(self, kind: &str, references: bool) -> bool {
        match self {
            Metric::Smape | Metric::SmapeReprojected => true,
            Metric::Flip | Metric::Mse | Metric::RelMse | Metric::Psnr | Metric::Cvvdp => {
                references
            }
            Metric::PathLength => kind == "Termination",
            Metric::MeanAbsBias => kind == "VolumeTransmittance",
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
            Metric::Cvvdp => None,
            // Method stats, by the name the method reports them under.
            Metric::PathLength | Metric::MeanAbsBias => {
                r.stats.iter().find(|(n, _)| n == self.name()).map(|s| s.1)
            }
        }
    }
}
