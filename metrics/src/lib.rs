//! Image metrics for temporal stability and accuracy.
//!
//! - [`smape`]: frame-to-frame flicker (SMAPE), optionally after motion-vector reprojection.
//! - [`flip`]: LDR-FLIP and HDR-FLIP (Andersson et al. 2020, 2021) against a reference, by the
//!   `flip-rs` crate (NVIDIA FLIP 1.7 ported).
//! - [`error`]: MSE, relative MSE, PSNR.
//! - [`cvvdp`]: ColorVideoVDP's JOD of a sequence against its reference, on a display model.
//! - [`region`]: named rectangles of interest; any per-pixel map can be averaged over one.
//! - [`compare`]: the `compare REFERENCE TEST` command.
//! - [`frames_csv`]: a run's frames.csv, its one writer and reader.
//! - [`reference_flip`]: NVIDIA's FLIP as a subprocess; [`synthetic`]: test images.

pub mod atomic;
pub mod colormap;
pub mod compare;
pub mod cvvdp;
pub mod error;
pub mod flip;
pub mod frames_csv;
pub mod image;
pub mod ordered_sum;
pub mod python;
pub mod reference_flip;
pub mod region;
pub mod smape;
pub mod synthetic;

pub use crate::image::{Image, load_image, write_exr, write_png_srgb};
pub use colormap::{magma, write_map_png};
pub use compare::{CompareOptions, compare};
pub use cvvdp::{CvvdpSettings, JodResult, jod};
pub use error::{mse, psnr, psnr_from_mse, relative_mse};
pub use flip::{DEFAULT_PPD, FlipResult, Percentiles, flip_hdr, flip_ldr, pixels_per_degree};
pub use region::Region;
pub use smape::{SmapeResult, smape, smape_reprojected};
