//! What VolumeTransmittance records besides every method's numbers: the bias and noise of its
//! transmittance image against the exact one (the jackknife paper's measures).

use frame::method::Statistic;

pub const STATISTICS: &[Statistic] = &[
    Statistic::frames("MeanAbsBias", "mean_abs_bias", "mean |bias| of the transmittance", ""),
    Statistic::frames("MeanStd", "mean_std", "mean std of the transmittance estimate", ""),
    // RMS over pixels of the noise-corrected bias (`media::image::rms_bias`): the bias the paper
    // reads from 2^18 spp, without the noise of a few dozen estimates.
    Statistic::frames("RmsBias", "rms_bias", "RMS noise-corrected bias of the transmittance", ""),
];
