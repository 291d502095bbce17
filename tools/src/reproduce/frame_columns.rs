//! Method statistics that a run's frames.csv holds but a suite's runs do not keep (declared
//! `Source::FramesReproduceOnly`, so not in `Metric::all()` and sweeps and baselines keep their
//! columns), e.g. the termination cache's `CacheMean`: read back per method and frame.

use anyhow::{Result, bail};
use frame::run_folder::RunFolder;
use playback::methods::Source;

use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;

use super::frames_csv::rows;

/// Whether `metric` is read here (its frames.csv column is its name).
pub fn reads(metric: Metric) -> bool {
    metric.statistic().is_some_and(|s| s.source == Source::FramesReproduceOnly)
}

/// Adds `metric`'s column of the seed's frames.csv to its methods' series (an empty cell: not
/// recorded); a run without the column is an error naming the file.
pub fn add(run: &mut SeedRun, metric: Metric) -> Result<()> {
    let Some(root) = &run.folder else {
        bail!("seed {}: no run folder to read {} from", run.seed, metric.name())
    };
    let path = RunFolder::new(root).frames_csv();
    let name = metric.name();
    let rows = rows(&path, |header| match header.iter().position(|h| *h == name) {
        Some(c) => Ok(vec![c]),
        None => bail!("{}: no method, frame or {name} column", path.display()),
    })?;
    for (method, frame, values) in rows {
        let Some(metrics) = run.methods.get_mut(&method) else { continue };
        let series = metrics.entry(name.to_string()).or_default();
        let f = frame as usize;
        if series.len() <= f {
            series.resize(f + 1, None);
        }
        series[f] = values[0];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;

    #[test]
    fn a_column_becomes_each_methods_series() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,cache_mean,cache_bias2\nvb,0,0.5,0.1\npt,0,,\nvb,1,0.75,0.2\npt,1,,\n",
        )
        .unwrap();
        let methods = ["vb", "pt"].into_iter().map(|m| (m.to_string(), BTreeMap::new())).collect();
        let mut run = SeedRun { seed: 1, methods, jod: BTreeMap::new(), folder: Some(dir.clone()) };
        add(&mut run, Metric::shipped("CacheMean")).unwrap();
        add(&mut run, Metric::shipped("CacheBias2")).unwrap();
        assert_eq!(run.methods["vb"]["cache_mean"], [Some(0.5), Some(0.75)]);
        assert_eq!(run.methods["vb"]["cache_bias2"], [Some(0.1), Some(0.2)]);
        // A method without the stat has no values, not zeros.
        assert_eq!(run.methods["pt"]["cache_mean"], [None, None]);
        assert_eq!(run.window_mean("vb", Metric::shipped("CacheMean"), 0..2), Some(0.625));
        let e = add(&mut run, Metric::shipped("CacheVariance")).unwrap_err().to_string();
        assert!(e.contains("no method, frame or cache_variance column"), "{e}");
    }
}
