//! What the SSS method records besides every method's numbers: its samples per SSS pixel, and
//! the PSNR over the SSS pixels against a converged pass that realtime-sss-thesis's Table 7.3
//! reports.

use frame::method::{Better, FolderInput, FolderStatistic, Source, Statistic};

pub const STATISTICS: &[Statistic] = &[
    Statistic::frames("SssSpp", "sss_mean_spp", "mean samples per SSS pixel", "samples"),
    // PSNR of luminance over the SSS pixels against another method's frames of the same run
    // (the claim's `against`), computed by `flicker reproduce` from the run folder's images
    // (`psnr_against.rs`).
    Statistic {
        better: Better::Higher,
        source: Source::Images(FolderStatistic {
            id: "sss_psnr_against",
            input: FolderInput::Against,
            compute: crate::psnr_against::psnr_against,
        }),
        ..Statistic::frames(
            "SssPsnr",
            crate::psnr_against::COLUMN,
            "PSNR over the SSS pixels",
            "dB",
        )
    },
];
