//! The `local` executor: a sweep's pending jobs on this machine, `jobs` at a time, each in its
//! own process (`flicker sweep job`, as on a cluster), its output in `DIR/logs/job_NNNN.log`.

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::Result;

use super::plan::{Plan, done_file, log_file};

pub struct LocalOutcome {
    pub ran: Vec<usize>,
    pub failed: Vec<usize>,
}

/// Runs the jobs without a record (all of them with `again`), `jobs` processes at a time.
pub fn run_local(dir: &Path, exe: &Path, jobs: usize, again: bool) -> Result<LocalOutcome> {
    let plan = Plan::load(dir)?;
    let pending: Vec<usize> = plan
        .jobs
        .iter()
        .map(|j| j.index)
        .filter(|&i| again || !done_file(dir, i).exists())
        .collect();
    std::fs::create_dir_all(dir.join("logs"))?;
    let next = AtomicUsize::new(0);
    let failed = Mutex::new(Vec::new());
    let workers = jobs.max(1).min(pending.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&index) = pending.get(k) else { break };
                    let ok = (|| -> Result<bool> {
                        let log = std::fs::File::create(log_file(dir, index))?;
                        let status = Command::new(exe)
                            .args(["sweep", "job"])
                            .arg(dir)
                            .args(["--index", &index.to_string(), "--quiet"])
                            .stdin(Stdio::null())
                            .stdout(log.try_clone()?)
                            .stderr(log)
                            .status()?;
                        Ok(status.success())
                    })()
                    .unwrap_or(false);
                    eprintln!(
                        "sweep {}: job {index} {}",
                        plan.sweep,
                        if ok { "done" } else { "FAILED" }
                    );
                    if !ok {
                        failed.lock().unwrap().push(index);
                    }
                }
            });
        }
    });
    let mut failed = failed.into_inner().unwrap();
    failed.sort_unstable();
    Ok(LocalOutcome { ran: pending, failed })
}
