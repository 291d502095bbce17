//! The participating-media methods of the jackknife-transmittance paper, over the `media`
//! crate's estimators and passes: primary-ray transmittance images per estimator
//! (`VolumeTransmittance`, [`transmittance`]) and volumetric path tracing with the paper's MIS
//! weights (`VolumePath`, [`path`]).

pub mod path;
pub mod recorded;
pub mod table1;
pub mod transmittance;
