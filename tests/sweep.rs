//! Sweeps end to end through the `flicker` program: a deterministic plan, bad sweep files at
//! file:line, and one 8-job sweep (sweeps/taa_alpha.ron) run by the local executor and as an
//! 8-task Slurm array on a one-node cluster this test starts on localhost (munged, slurmctld,
//! slurmd; Debian's `slurm-wlm` and `munge`, installed by scripts/setup-tests.sh), and through GNU
//! parallel reading the plan's job file. The merged summaries must agree in every number but
//! the timings. `flicker reproduce --plan` of a small claims file runs on the same cluster and
//! on the local executor, and `--judge-from` must write the report of a run played in one
//! process. If the cluster does not come up the test fails with the daemons' logs.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn flicker(args: &[&str]) -> Output {
    flicker_with_env(args, &[])
}

fn flicker_with_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("flicker runs")
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-sweep-{name}-")).tempdir().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what} failed ({}):\nstdout: {}\nstderr: {}",
        o.status,
        text(&o.stdout),
        text(&o.stderr)
    );
}

fn sweep_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/taa_alpha.ron")
}

/// summary.json without its `timing` entries (wall-clock times differ between any two runs).
fn numbers(dir: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for c in v["configurations"].as_array_mut().unwrap() {
        c.as_object_mut().unwrap().remove("timing");
    }
    v
}

#[test]
fn plan_is_deterministic() {
    let tmp = scratch("plan");
    let dir = tmp.path().to_path_buf();
    let (a, b) = (dir.join("a"), dir.join("nested/b"));
    for out in [&a, &b] {
        ok(
            &flicker(&[
                "sweep",
                "plan",
                sweep_file().to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ]),
            "sweep plan",
        );
    }
    let plan_a = std::fs::read(a.join("plan.json")).unwrap();
    assert_eq!(
        plan_a,
        std::fs::read(b.join("plan.json")).unwrap(),
        "two plans of one sweep file differ"
    );
    let plan: serde_json::Value = serde_json::from_slice(&plan_a).unwrap();
    let jobs: Vec<(String, u64)> = plan["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| (j["point"].as_str().unwrap().to_string(), j["seed"].as_u64().unwrap()))
        .collect();
    // Points in file order, seeds fastest.
    let expected: Vec<(String, u64)> = ["0.05", "0.1", "0.3", "1.0"]
        .iter()
        .flat_map(|a| [1, 2].map(|s| (format!("taa.alpha={a}"), s)))
        .collect();
    assert_eq!(jobs, expected);
    // The executors' files name every job once.
    let lines = std::fs::read_to_string(a.join("jobs.txt")).unwrap();
    assert_eq!(lines.lines().count(), 8);
    assert!(
        lines
            .lines()
            .enumerate()
            .all(|(i, l)| l.contains(&format!("sweep job '{}' --index {i} ", a.display()))),
        "{lines}"
    );
    assert!(
        std::fs::read_to_string(a.join("sweep.sbatch")).unwrap().contains("#SBATCH --array=0-7\n")
    );
    // Planning again into the same folder is allowed; another sweep's plan there is not.
    ok(
        &flicker(&["sweep", "plan", sweep_file().to_str().unwrap(), "--out", a.to_str().unwrap()]),
        "sweep plan again",
    );
    let other = dir.join("other.ron");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("suites/scenarios/smoke_cornell.ron");
    let body = std::fs::read_to_string(sweep_file())
        .unwrap()
        .replace("[1, 2]", "[1, 3]")
        .replace("../suites/scenarios/smoke_cornell.ron", scenario.to_str().unwrap());
    std::fs::write(&other, body).unwrap();
    let o = flicker(&["sweep", "plan", other.to_str().unwrap(), "--out", a.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("holds another sweep's plan"), "{}", text(&o.stderr));
}

#[test]
fn shipped_sweeps_plan() {
    let tmp = scratch("shipped");
    let dir = tmp.path().to_path_buf();
    let sweeps = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&sweeps)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 2, "{files:?}");
    for f in files {
        let out = dir.join(f.file_stem().unwrap());
        ok(
            &flicker(&["sweep", "plan", f.to_str().unwrap(), "--out", out.to_str().unwrap()]),
            &format!("sweep plan {}", f.display()),
        );
    }
}

#[test]
fn bad_sweep_files_name_file_and_line() {
    let tmp = scratch("bad");
    let dir = tmp.path().to_path_buf();
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("suites/scenarios/smoke_cornell.ron");
    let head = format!(
        "Sweep(\n    cases: [(name: \"c\", scenario: \"{}\", seeds: [1], methods: [\"taa\"])],\n",
        scenario.display()
    );
    let cases = [
        // A field TAA does not have: found when the plan builds the jobs, reported at the axis.
        (
            format!("{head}    grid: [\n        (\"taa.alpah\", [0.1]),\n    ],\n)"),
            4,
            "no field 'alpah'",
        ),
        // A method the case does not run.
        (
            format!("{head}    grid: [\n        (\"pt_1spp.spp\", [2]),\n    ],\n)"),
            4,
            "no method labelled 'pt_1spp'",
        ),
        // A value of the wrong type.
        (
            format!(
                "{head}    list: [\n        [(\"taa.alpha\", 0.1)],\n        [(\"taa.jitter_length\", \"many\")],\n    ],\n)"
            ),
            5,
            "jitter_length",
        ),
        // RON syntax.
        (
            format!("{head}    grid: [\n        (\"taa.alpha\" [0.1]),\n    ],\n)"),
            4,
            "Expected comma",
        ),
    ];
    for (i, (body, line, what)) in cases.iter().enumerate() {
        let file = dir.join(format!("bad{i}.ron"));
        std::fs::write(&file, body).unwrap();
        let out = dir.join(format!("out{i}"));
        let o = flicker(&["sweep", "plan", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("{}:{line}:", file.display())),
            "expected {}:{line}: in: {err}",
            file.display()
        );
        assert!(err.contains(what), "expected '{what}' in: {err}");
        assert!(!out.join("plan.json").exists(), "a bad sweep file must not leave a plan");
    }
}

/// A free TCP port on localhost (bound, then released for the daemon).
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// munged, slurmctld and slurmd in the foreground as this test's children, their state, logs
/// and sockets in `dir`. Dropping it cancels the cluster's jobs and ends the daemons.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<(&'static str, Child)>,
}

impl Cluster {
    fn slurm(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// Every log the daemons wrote, for a failure message.
    fn logs(&self) -> String {
        let mut out = String::new();
        for name in [
            "munged.log",
            "munged.stderr",
            "slurmctld.log",
            "slurmctld.stderr",
            "slurmd.log",
            "slurmd.stderr",
        ] {
            let body = std::fs::read_to_string(self.dir.join(name))
                .unwrap_or_else(|e| format!("(unreadable: {e})"));
            out.push_str(&format!("\n--- {name} ---\n{body}"));
        }
        out
    }

    fn spawn(&mut self, name: &'static str, program: &str, args: &[&str]) {
        let stderr = std::fs::File::create(self.dir.join(format!("{name}.stderr"))).unwrap();
        // The daemons live in /usr/sbin, which a non-login PATH may lack.
        let program = ["/usr/sbin", "/sbin"]
            .iter()
            .map(|d| Path::new(d).join(program))
            .find(|p| p.exists())
            .unwrap_or_else(|| PathBuf::from(program));
        let program = program.to_str().unwrap();
        let mut c = self.slurm(program);
        c.args(args).stdin(Stdio::null()).stdout(stderr.try_clone().unwrap()).stderr(stderr);
        match c.spawn() {
            Ok(child) => self.daemons.push((name, child)),
            Err(e) => panic!(
                "cannot start {program} ({e}); install Debian's slurm-wlm and munge (scripts/setup-tests.sh){}",
                self.logs()
            ),
        }
    }

    fn start(dir: PathBuf) -> Cluster {
        use std::os::unix::fs::PermissionsExt;
        let munge = dir.join("munge");
        std::fs::create_dir_all(&munge).unwrap();
        // munged refuses a key others can read and a socket folder others can write.
        std::fs::set_permissions(&munge, std::fs::Permissions::from_mode(0o711)).unwrap();
        let mut key = vec![0u8; 1024];
        std::io::Read::read_exact(&mut std::fs::File::open("/dev/urandom").unwrap(), &mut key)
            .unwrap();
        let key_file = munge.join("munge.key");
        std::fs::write(&key_file, &key).unwrap();
        std::fs::set_permissions(&key_file, std::fs::Permissions::from_mode(0o600)).unwrap();
        for sub in ["state", "spool"] {
            std::fs::create_dir_all(dir.join(sub)).unwrap();
        }
        let host =
            text(&Command::new("hostname").arg("-s").output().expect("hostname runs").stdout)
                .trim()
                .to_string();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let d = dir.display();
        let conf = dir.join("slurm.conf");
        // No cgroups in a container: processes tracked by parent id, no task plugin.
        std::fs::write(
            &conf,
            format!(
                "ClusterName=flickertest\nSlurmctldHost={host}(127.0.0.1)\nSlurmUser=root\nSlurmdUser=root\n\
                 SlurmctldPort={}\nSlurmdPort={}\nAuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={d}/munge/munge.sock\n\
                 StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\nSlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
                 SlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
                 JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\nMpiDefault=none\nSwitchType=switch/none\n\
                 SchedulerType=sched/builtin\nSelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nReturnToService=2\n\
                 NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\nPartitionName=flicker Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
                free_port(),
                free_port()
            ),
        )
        .unwrap();
        let mut cluster = Cluster { dir: dir.clone(), conf, daemons: Vec::new() };
        let m = |f: &str| format!("{d}/munge/{f}");
        cluster.spawn(
            "munged",
            "munged",
            &[
                "--foreground",
                "--force",
                &format!("--key-file={}", m("munge.key")),
                &format!("--socket={}", m("munge.sock")),
                &format!("--pid-file={}", m("munged.pid")),
                &format!("--seed-file={}", m("munged.seed")),
                &format!("--log-file={d}/munged.log"),
            ],
        );
        cluster.wait_for("munged's socket", || dir.join("munge/munge.sock").exists());
        cluster.spawn("slurmctld", "slurmctld", &["-D", "-i"]);
        // -N: the node's name as slurm.conf has it, whatever `hostname` would resolve to.
        cluster.spawn("slurmd", "slurmd", &["-D", "-N", &host]);
        let conf = cluster.conf.clone();
        cluster.wait_for("the node to be idle", || {
            Command::new("sinfo")
                .env("SLURM_CONF", &conf)
                .args(["-h", "-o", "%T"])
                .output()
                .is_ok_and(|o| text(&o.stdout).trim() == "idle")
        });
        cluster
    }

    fn wait_for(&mut self, what: &str, ready: impl Fn() -> bool) {
        let start = Instant::now();
        while !ready() {
            let exited = self
                .daemons
                .iter_mut()
                .find_map(|(name, child)| child.try_wait().ok().flatten().map(|s| (*name, s)));
            if let Some((name, status)) = exited {
                panic!("{name} exited ({status}) while waiting for {what}{}", self.logs());
            }
            if start.elapsed() > Duration::from_secs(60) {
                panic!("the Slurm cluster did not come up: no {what} after 60 s{}", self.logs());
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = self.slurm("scancel").args(["--user", "root"]).output();
        for (_, child) in self.daemons.iter_mut().rev() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// A claims file of two claims on the smoke suite's Cornell box at 16x9 (TAA against 1 spp
/// path tracing over 2 seeds): `DIR/claims/tiny.ron`.
fn tiny_claims(dir: &Path) -> PathBuf {
    let claims = dir.join("claims");
    std::fs::create_dir_all(&claims).unwrap();
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("suites/scenarios/smoke_cornell.ron");
    std::fs::write(
        claims.join("tiny.ron"),
        format!(
            "Claims(\n    paper: \"tiny\",\n    title: \"Tiny\",\n    cases: [\n        (name: \"cornell\", scenario: \"{}\", seeds: [1, 2], methods: [\"pt_1spp\", \"taa\"],\n         smoke: (resolution: (16, 9), frames: 3)),\n    ],\n    claims: [\n        (id: \"taa_steadier\", claim: \"c\", source: \"s\", paper: \"p\", case: \"cornell\", statistic: (metric: Smape, window: Overall), comparison: Below(method: \"taa\", than: \"pt_1spp\"), smallest_effect: Relative(0.05), smallest_effect_from: \"s\"),\n        (id: \"taa_flip\", claim: \"c\", source: \"s\", paper: \"p\", case: \"cornell\", statistic: (metric: Flip, window: Overall), comparison: Value(method: \"taa\", value: 0.3), smallest_effect: Absolute(0.3), smallest_effect_from: \"p\"),\n    ],\n)\n",
            scenario.display()
        ),
    )
    .unwrap();
    claims
}

/// `flicker reproduce tiny --scale smoke` with `extra`.
fn reproduce_tiny(claims: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["reproduce", "tiny", "--scale", "smoke", "--quiet", "--claims"];
    args.push(claims.to_str().unwrap());
    args.extend_from_slice(extra);
    flicker(&args)
}

/// reproduce.md without its first lines (title and the command that made it).
fn claims_report(dir: &Path) -> String {
    let md = std::fs::read_to_string(dir.join("reproduce.md")).unwrap();
    md.lines().skip(3).collect::<Vec<_>>().join("\n")
}

#[test]
fn sweep_runs_locally_and_on_slurm_with_identical_numbers() {
    let tmp = scratch("slurm");
    let dir = tmp.path().to_path_buf();
    let sweep = sweep_file();
    let (local, slurm) = (dir.join("local"), dir.join("slurm"));

    // Local executor: plan, 8 jobs two at a time, merge. One CPU thread per job here and the
    // default elsewhere, so that a metric whose value depends on the thread count (an unordered
    // parallel sum) shows as a difference below.
    let run =
        ["sweep", "run", sweep.to_str().unwrap(), "--out", local.to_str().unwrap(), "--jobs", "2"];
    ok(&flicker_with_env(&run, &[("RAYON_NUM_THREADS", "1")]), "sweep run (local)");
    let local_numbers = numbers(&local);
    // A failed job is rerun alone: without its record the merge names it, `local` runs only it.
    std::fs::remove_file(local.join("done/job_0003.json")).unwrap();
    let o = flicker(&["sweep", "merge", local.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("1 of 8 jobs have not finished (3)"), "{}", text(&o.stderr));
    let o = flicker(&["sweep", "local", local.to_str().unwrap()]);
    ok(&o, "sweep local (rerun)");
    assert_eq!(
        text(&o.stderr).matches(" done").count(),
        1,
        "only job 3 reruns: {}",
        text(&o.stderr)
    );
    ok(&flicker(&["sweep", "merge", local.to_str().unwrap()]), "sweep merge (local, after rerun)");
    assert_eq!(numbers(&local), local_numbers, "a rerun job changed the merged numbers");

    // Reproduce: played in one process, then as jobs of the local executor (judging before
    // they ran names the pending jobs).
    let claims = tiny_claims(&dir);
    let history = dir.join("history");
    let (played, by_jobs, on_slurm) = (dir.join("played"), dir.join("jobs"), dir.join("rslurm"));
    let h = ["--history", history.to_str().unwrap()];
    ok(
        &reproduce_tiny(&claims, &[&["--out", played.to_str().unwrap()], &h[..]].concat()),
        "reproduce (played)",
    );
    let reference = claims_report(&played);
    assert!(
        reference.contains("| taa_steadier") && reference.contains("| taa_flip"),
        "{reference}"
    );
    for d in [&by_jobs, &on_slurm] {
        let o = reproduce_tiny(&claims, &["--plan", d.to_str().unwrap()]);
        ok(&o, "reproduce --plan");
        assert!(text(&o.stdout).contains("planned 2 jobs"), "{}", text(&o.stdout));
    }
    let judge = |d: &Path| {
        reproduce_tiny(&claims, &[&["--judge-from", d.to_str().unwrap()], &h[..]].concat())
    };
    let o = judge(&by_jobs);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o.stderr).contains("2 of 2 jobs have not finished (0,1)"), "{}", text(&o.stderr));
    // Another scale than planned is refused.
    let o = flicker(&[
        "reproduce",
        "tiny",
        "--scale",
        "lab",
        "--claims",
        claims.to_str().unwrap(),
        "--judge-from",
        by_jobs.to_str().unwrap(),
    ]);
    assert!(
        text(&o.stderr).contains("holds the jobs of `flicker reproduce tiny --scale smoke`"),
        "{}",
        text(&o.stderr)
    );
    ok(
        &flicker(&["sweep", "local", by_jobs.to_str().unwrap(), "--jobs", "2"]),
        "sweep local (reproduce jobs)",
    );
    ok(&judge(&by_jobs), "reproduce --judge-from (local executor)");
    assert_eq!(claims_report(&by_jobs), reference, "judged from the local executor's jobs");

    // Slurm: the same plan as an 8-task array on a one-node cluster.
    ok(
        &flicker(&["sweep", "plan", sweep.to_str().unwrap(), "--out", slurm.to_str().unwrap()]),
        "sweep plan (slurm)",
    );
    let cluster = Cluster::start(dir.join("cluster"));
    let o = cluster
        .slurm("sbatch")
        .args(["--wait", "--parsable"])
        .arg(slurm.join("sweep.sbatch"))
        .output()
        .expect("sbatch runs");
    let task_logs: Vec<PathBuf> = std::fs::read_dir(slurm.join("logs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("slurm_"))
        .collect();
    let outputs: String = task_logs
        .iter()
        .map(|p| {
            format!("\n--- {} ---\n{}", p.display(), std::fs::read_to_string(p).unwrap_or_default())
        })
        .collect();
    assert!(
        o.status.success(),
        "sbatch --wait failed ({}): {}{outputs}{}",
        o.status,
        text(&o.stderr),
        cluster.logs()
    );
    let job_id = text(&o.stdout).trim().to_string();
    let o = cluster
        .slurm("sbatch")
        .args(["--wait", "--parsable"])
        .arg(on_slurm.join("sweep.sbatch"))
        .output()
        .expect("sbatch runs");
    assert!(
        o.status.success(),
        "sbatch --wait (reproduce) failed: {}{}",
        text(&o.stderr),
        cluster.logs()
    );
    let reproduce_id = text(&o.stdout).trim().to_string();
    drop(cluster);
    for i in 0..2 {
        assert!(
            on_slurm.join(format!("logs/slurm_{reproduce_id}_{i}.out")).exists(),
            "no output of reproduce task {i}"
        );
    }
    ok(&judge(&on_slurm), "reproduce --judge-from (slurm)");
    assert_eq!(claims_report(&on_slurm), reference, "judged from the Slurm array's jobs");
    // Each judged run appended a record to the history, as the played one did.
    let records = tools::history::read(&history).unwrap();
    assert_eq!(records.len(), 3);
    assert!(records.iter().all(|(_, r)| r.entries.len() == 2 && r.scale == "smoke"));
    // Every array task left its Slurm output file, so Slurm (not this test) ran the jobs.
    for i in 0..8 {
        assert!(
            slurm.join(format!("logs/slurm_{job_id}_{i}.out")).exists(),
            "no output of array task {i}{outputs}"
        );
    }
    ok(&flicker(&["sweep", "merge", slurm.to_str().unwrap()]), "sweep merge (slurm)");

    let slurm_numbers = numbers(&slurm);
    assert_eq!(
        slurm_numbers, local_numbers,
        "local and Slurm runs of one sweep merged to different numbers"
    );

    // GNU parallel: the plan's job file, one shell command per line, two at a time.
    let par = dir.join("parallel");
    ok(
        &flicker(&["sweep", "plan", sweep.to_str().unwrap(), "--out", par.to_str().unwrap()]),
        "sweep plan (parallel)",
    );
    let jobs = std::fs::File::open(par.join("jobs.txt")).unwrap();
    let o = Command::new("parallel")
        .args(["--jobs", "2", "--halt", "now,fail=1"])
        .stdin(jobs)
        .output()
        .expect("GNU parallel runs (scripts/setup-tests.sh installs it)");
    ok(&o, "parallel < jobs.txt");
    ok(&flicker(&["sweep", "merge", par.to_str().unwrap()]), "sweep merge (parallel)");
    assert_eq!(
        numbers(&par),
        local_numbers,
        "local and GNU parallel runs of one sweep merged to different numbers"
    );
    // The summary holds what the sweep asked for: 4 configurations of 2 seeds, FLIP in (0, 1).
    let configs = slurm_numbers["configurations"].as_array().unwrap();
    assert_eq!(configs.len(), 4);
    for c in configs {
        assert_eq!(c["seeds"], serde_json::json!([1, 2]));
        let flip = c["metrics"]["flip"]["mean"].as_f64().unwrap();
        assert!(flip > 0.0 && flip < 1.0, "{c}");
    }
    // α = 1 keeps no history: it flickers more than α = 0.05 (SMAPE against the previous frame).
    let smape = |i: usize| configs[i]["metrics"]["smape"]["mean"].as_f64().unwrap();
    assert!(smape(3) > smape(0), "{configs:?}");
    for f in ["speed_vs_flip.svg", "speed_vs_flip.png", "report.md"] {
        assert!(slurm.join(f).exists(), "merge wrote no {f}");
    }
}
