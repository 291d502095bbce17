//! A method's frame time as it would spend it alone. Methods of one run may share a cache and
//! its passes (the NIRC modes share one cache: its camera paths, training, EMA and reliability
//! update run once a frame, and every mode books them, as each would pay them alone). A paper
//! that times each method in its own run charges a method only the shared passes it needs:
//! `not_run` names, per method, the shared passes it would not run alone, and its `FrameMs` is
//! the frame's passes less those, read back from the run's frames.csv.

use anyhow::{Context, Result, bail};
use frame::run_folder::RunFolder;

use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;

use super::pass_ms::pass_times;

/// Each method of `not_run` gets `FrameMs` less its passes not run alone, per frame. A frame
/// with a time had every pass it booked timed, so an empty cell there is a pass not booked that
/// frame (a rejected training step has no reliability update): nothing to leave out.
pub fn leave_out(run: &mut SeedRun, not_run: &[(String, Vec<String>)]) -> Result<()> {
    let Some(root) = &run.folder else {
        bail!("seed {}: no run folder to read pass times from", run.seed)
    };
    let csv = RunFolder::new(root).frames_csv();
    let key = Metric::FrameMs.name();
    for (method, passes) in not_run {
        let rows = pass_times(&csv, passes)?;
        let series = run
            .methods
            .get_mut(method)
            .and_then(|m| m.get_mut(key))
            .with_context(|| format!("seed {}: no {key} of {method}", run.seed))?;
        for (_, frame, times) in rows.iter().filter(|(m, ..)| m == method) {
            if let Some(total) = series.get_mut(*frame as usize) {
                let left_out: f64 = times.iter().map(|t| t.unwrap_or(0.0)).sum();
                *total = total.map(|t| t - left_out);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;

    /// Only the listed method loses only the listed pass, frame by frame (none where the frame
    /// did not book it); a pass the run does not have is an error naming it.
    #[test]
    fn a_method_is_charged_only_the_passes_it_runs() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,cpu_ms,gpu_ms_total,gpu_ms_train,gpu_ms_reliability,smape\n\
             ema,0,9.0,10.0,6.0,1.5,\n\
             blend,0,9.0,11.0,6.0,1.5,\n\
             ema,1,9.0,12.0,6.0,,0.1\n\
             blend,1,9.0,13.0,6.0,2.0,0.1\n",
        )
        .unwrap();
        let series = |a: f64, b: f64| {
            BTreeMap::from([(Metric::FrameMs.name().to_string(), vec![Some(a), Some(b)])])
        };
        let methods = BTreeMap::from([
            ("ema".to_string(), series(10.0, 12.0)),
            ("blend".to_string(), series(11.0, 13.0)),
        ]);
        let mut run = SeedRun { seed: 1, methods, jod: BTreeMap::new(), folder: Some(dir.clone()) };
        leave_out(&mut run, &[("ema".into(), vec!["reliability".into()])]).unwrap();
        let ms = |m: &str| run.methods[m]["frame_ms"].clone();
        assert_eq!(ms("ema"), [Some(8.5), Some(12.0)]);
        assert_eq!(ms("blend"), [Some(11.0), Some(13.0)]);
        let e = leave_out(&mut run, &[("ema".into(), vec!["ema_update".into()])]).unwrap_err();
        assert!(e.to_string().contains("no column of pass 'ema_update'"), "{e}");
    }
}
