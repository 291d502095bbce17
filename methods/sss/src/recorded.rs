//! What the SSS method records besides every method's numbers: its samples per SSS pixel, and
//! the PSNR over the SSS pixels against a converged pass that realtime-sss-thesis's Table 7.3
//! reports.

use frame::method::{Better, ImageStatistic, Source, Statistic};

pub const STATISTICS: &[Statistic] = &[
    Statistic::frames("SssSpp", "sss_mean_spp", "mean samples per SSS pixel", "samples"),
    // PSNR of luminance over the SSS pixels against another method's frames of the same run
    // (the claim's `against`), computed by `flicker reproduce` from the run folder's images.
    Statistic {
        better: Better::Higher,
        source: Source::Images(ImageStatistic::PsnrAgainst),
        ..Statistic::frames("SssPsnr", "sss_psnr", "PSNR over the SSS pixels", "dB")
    },
];
