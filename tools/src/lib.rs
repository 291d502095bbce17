//! Tools that drive many scenario runs through `systems::playback`: regression suites
//! (`suite`: cases over seeds, gates judged against a blessed baseline) and parameter sweeps
//! (`sweep`: jobs planned for local, GNU parallel or Slurm execution, then merged).

pub mod reproduce;
pub mod ron_file;
pub mod suite;
pub mod sweep;
