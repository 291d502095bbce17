//! Tools that drive many scenario runs through `playback::play`: regression suites
//! (`suite`: cases over seeds, gates judged against a blessed baseline) and parameter sweeps
//! (`sweep`: jobs planned for local, GNU parallel or Slurm execution, then merged); `measure`
//! gives frames from any renderer the metrics and report of a run; `export` writes a scenario as
//! a package (glTF, references, a denoiser's inputs) for any renderer; `gallery` writes the guide's
//! pages of failure cases and of speed against accuracy from runs it plays.

pub mod export;
pub mod gallery;
pub mod history;
pub mod measure;
pub mod reproduce;
pub mod ron_file;
pub mod suite;
pub mod sweep;
