//! The statistics a method computes from a run folder's images (`Source::Images`: its
//! `FolderStatistic`, in the method's crate), run for `flicker reproduce` by the statistic's
//! declaration alone: the seed's run folder, frames, events and the claim's `against` in, each
//! method's per-frame series out.

use anyhow::{Result, bail};
use playback::methods::FolderStatistic;
use playback::methods::registry;

use crate::suite::measurement::SeedRun;

/// Adds what `statistic` computes over `run`'s folder (`frames` frames, the case's `events`) to
/// the methods of the run it names.
pub fn add(
    run: &mut SeedRun,
    statistic: &FolderStatistic,
    frames: u32,
    events: &[u32],
    against: Option<&str>,
) -> Result<()> {
    let Some(root) = &run.folder else {
        let names: Vec<&str> = registry::statistics()
            .into_iter()
            .filter(|s| matches!(s.source, playback::methods::Source::Images(i) if i == *statistic))
            .map(|s| s.column)
            .collect();
        bail!("seed {}: no run folder to read {} from", run.seed, names.join(", "))
    };
    let methods: Vec<String> = run.methods.keys().cloned().collect();
    let folder = playback::methods::FolderRun {
        folder: root,
        seed: run.seed,
        methods: &methods,
        frames,
        events,
        against,
    };
    for (method, column, values) in (statistic.compute)(&folder)? {
        if let Some(metrics) = run.methods.get_mut(&method) {
            metrics.insert(column.to_string(), values);
        }
    }
    Ok(())
}
