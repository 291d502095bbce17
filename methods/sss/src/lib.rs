//! Screen-space subsurface scattering (../shared/seeds/realtime-sss-thesis.txt, Xie 2022):
//! Burley's profile (`profile`) and its inverse cdfs (`inverse`), the pass's f32 sample math
//! (`sampling`), single pass variance guiding (`spvg`), control variates in the sample-count
//! domain (`control_variates`), the pass on the CPU (`screen_pass`) and in WGSL (`gpu`), the
//! separable baseline (`separable`), prefiltered irradiance MIPs for AFIS (`prefilter`), the
//! hybrid of the two (`hybrid`). The random-walk reference and the path-traced ground truth of a
//! flat plane built on it are test support (tests/support/).
//! The file map is in this crate's README.md; settings, results and departures in
//! docs/methods/sss.md.

pub mod control_variates;
pub mod direct;
pub mod frame_input;
pub mod gpu;
pub mod hybrid;
pub mod inverse;
pub mod pixel;
pub mod prefilter;
pub mod profile;
pub mod psnr_against;
pub mod reproject;
pub mod sampling;
pub mod screen_pass;
pub mod separable;
pub mod split;
pub mod spvg;

pub use control_variates::EmCovariance;
pub use direct::IrradianceSource;
pub use frame_input::SssFrame;
pub use hybrid::Hybrid;
pub use pixel::{PixelHistory, PixelResult};
pub use prefilter::Prefilter;
pub use profile::BurleyProfile;
pub use screen_pass::{SssPassSettings, SssVariant};
pub use split::{DistantCount, Split};
pub use spvg::{SpvgHistory, SpvgSettings};

pub mod plugin;
pub mod recorded;
pub use plugin::Plugin;
