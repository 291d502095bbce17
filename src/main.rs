//! `flicker`: play scenarios of dynamic scenes, measure how light-transport caches behave.

mod compare_args;
mod export_args;
mod measure_args;
mod report_args;
mod runtime_dir;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use playback::play::{self, Overrides, RunOptions};

#[derive(Parser)]
#[command(
    name = "flicker",
    version,
    about = "A lab for the temporal stability of real-time light transport"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Play a scenario: render every frame of every method, the references, timings and metrics.
    ///
    /// SIGINT or SIGTERM (Ctrl-C) stops it after the frame on hand: what it has is written,
    /// manifest.json says `interrupted` with the last complete frame, the exit code is 130, and
    /// `--resume` continues it. A second signal stops it at once.
    Run {
        /// The scenario file (RON), e.g. scenarios/showcase.ron
        #[arg(required_unless_present = "resume")]
        scenario: Option<PathBuf>,
        /// Continue the interrupted run in this folder from its last complete frame, with its
        /// own scenario and settings (it is played again unwritten up to there: the frames come
        /// out as those of an uninterrupted run).
        #[arg(long, value_name = "RUN", conflicts_with_all = ["scenario", "frames", "resolution", "spp", "seed", "out"])]
        resume: Option<PathBuf>,
        /// Number of recorded frames (overrides the scenario).
        #[arg(long)]
        frames: Option<u32>,
        /// Image size as WIDTHxHEIGHT, e.g. 160x90 (overrides the scenario).
        #[arg(long, value_parser = parse_resolution)]
        resolution: Option<(u32, u32)>,
        /// Samples per pixel of every method (overrides the scenario).
        #[arg(long)]
        spp: Option<u32>,
        /// Random seed (overrides the scenario).
        #[arg(long)]
        seed: Option<u64>,
        /// Output folder (overrides the scenario).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Cache folder: references and NIRC warm starts [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
        #[arg(long)]
        cache_dir: Option<PathBuf>,
        /// Do not draw the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Print the frame's systems in execution order, grouped by stage, for a scenario's methods.
    Schedule {
        /// The scenario file (RON), e.g. scenarios/light_rotation_cornell_box.ron
        scenario: PathBuf,
    },
    /// List the built-in scenes: each one's entities, lights and materials, the names that
    /// animations and events address.
    Scenes,
    /// Compare a test image with a reference (PNG or EXR): mean FLIP, SMAPE, PSNR, error map.
    Compare(compare_args::CompareArgs),
    /// Rebuild summary.json, the charts and report.html of a run folder.
    Report(report_args::ReportArgs),
    /// Write a scenario as a package any renderer can play: the scene and its motion as glTF
    /// (.glb), per-frame camera and light records, the references and a denoiser's inputs
    /// (EXR), and a manifest that `flicker measure --scenario DIR` reads (docs/export.md).
    Export(export_args::ExportArgs),
    /// Measure frames from any renderer (EXR or PNG sequences) against a reference: a run folder
    /// with frames.csv, summary.json (with JOD) and the report, as `flicker run` writes.
    Measure(measure_args::MeasureArgs),
    /// Regression suites: play cases over seeds and judge gates against a blessed baseline.
    Suite {
        #[command(subcommand)]
        action: SuiteAction,
    },
    /// Play what a seed paper's claims need (claims/PAPER.ron) over seeds and judge each claim:
    /// reproduced, not reproduced or inconclusive against its smallest effect that matters (not
    /// comparable, with the reason, where there are no data); writes reproduce.md and .html.
    Reproduce {
        /// A paper (the stem of its claims file, e.g. reliability-weighted-nirc) or `all`.
        paper: String,
        /// smoke (tiny: about two minutes a paper on 2 cores), lab (the scenarios as shipped) or
        /// paper (the paper's sizes where the claims file gives them).
        #[arg(long, default_value = "lab", value_parser = tools::reproduce::Scale::parse)]
        scale: tools::reproduce::Scale,
        /// Seeds per case (at least 2) [default: each case's own list].
        #[arg(long)]
        seeds: Option<usize>,
        /// Output folder [default: runs/reproduce_PAPER_SCALE].
        #[arg(long)]
        out: Option<PathBuf>,
        /// The folder of claims files.
        #[arg(long, default_value = "claims")]
        claims: PathBuf,
        /// Cache folder for references [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
        #[arg(long)]
        cache_dir: Option<PathBuf>,
        /// Do not draw progress bars.
        #[arg(long)]
        quiet: bool,
        /// Play nothing: write the cases' seeds as jobs into DIR (plan.json, jobs.txt for GNU
        /// parallel, sweep.sbatch for a Slurm array), run them with `flicker sweep local DIR`,
        /// `parallel < DIR/jobs.txt` or `sbatch DIR/sweep.sbatch`, then judge with --judge-from.
        #[arg(long, value_name = "DIR", conflicts_with = "judge_from")]
        plan: Option<PathBuf>,
        /// Play nothing: judge the finished jobs planned in DIR with --plan (the same paper,
        /// --scale and --seeds); the report goes to --out or DIR.
        #[arg(long, value_name = "DIR")]
        judge_from: Option<PathBuf>,
        #[command(flatten)]
        history: HistoryArgs,
    },
    /// Each claim's, gate's and bench ratio's value and interval across commits, from the
    /// results history: a table (printed, and OUT/history.md) and a chart per series
    /// (OUT/charts/), flagging a verdict that changed from one commit to the next and a drift
    /// beyond the claim's margin while the verdict held.
    History {
        /// The results history [default: results/history].
        #[arg(long, value_name = "DIR", default_value = tools::history::DEFAULT_DIR)]
        history: PathBuf,
        /// Where history.md and the charts go.
        #[arg(long, default_value = "runs/history")]
        out: PathBuf,
        /// Only the series whose id contains TEXT, or of this kind (reproduce, suite, bench)
        /// or scale.
        #[arg(long, value_name = "TEXT")]
        only: Option<String>,
        /// Exit with code 1 when a series' latest commit changed verdict or drifted against
        /// the commit before (for CI).
        #[arg(long)]
        fail_on_change: bool,
    },
    /// Guide pages made from runs played by this one command: `failures` (each method's failure
    /// case: its frame beside the baseline's and the reference, its numbers, the command that
    /// reproduces them) and `speed` (speed against accuracy: the charts and numbers of one run).
    Gallery {
        #[command(subcommand)]
        page: GalleryPage,
    },
    /// Parameter sweeps: a grid or list over method parameters, cases and seeds, one run folder
    /// per job, run here, with GNU parallel or as a Slurm array, merged into one summary.
    Sweep {
        #[command(subcommand)]
        action: SweepAction,
    },
    /// Measure speed: BVH traversal (WGSL vs obvhs CPU), frame time per pass, FLIP and SMAPE.
    Bench {
        /// Also write the Markdown table to this file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Rays per traversal measurement.
        #[arg(long, default_value_t = 1 << 18)]
        rays: u32,
        /// Timed frames per scene and resolution.
        #[arg(long, default_value_t = 5)]
        frames: u32,
        /// Skip the image-metric benchmark (FLIP against NVIDIA's flip-evaluator, SMAPE).
        #[arg(long)]
        no_metrics: bool,
        /// Only the image-metric benchmark (SMAPE, FLIP, JOD, cvvdp where installed; no GPU).
        #[arg(long, conflicts_with = "no_metrics")]
        metrics_only: bool,
        /// Timed repetitions of each image metric (the best is reported).
        #[arg(long, default_value_t = 3)]
        repeats: u32,
        /// Measure device memory instead: each method's buffers and textures at 160x90 and
        /// 320x180, the scene's share, and one NIRC cache's buffers.
        #[arg(long, conflicts_with = "nirc")]
        memory: bool,
        /// Measure the neural incident radiance cache instead: training and inference GFLOP/s
        /// against this adapter's FMA ceiling, and the blend's overhead.
        #[arg(long)]
        nirc: bool,
        /// With --nirc: training records per step.
        #[arg(long, default_value_t = 4096)]
        nirc_batch: u32,
        /// With --nirc: queries per inference.
        #[arg(long, default_value_t = 16384)]
        nirc_queries: u32,
        /// With --nirc: timed whole frames per predictor (High-LR, EMA-only, blend) in the
        /// Cornell box, the paper's Table 1 (a multiple of 6 balances their order; the blend's
        /// interval needs at least 2); 0 skips them.
        #[arg(long, default_value_t = 18)]
        nirc_frames: u32,
        /// With --nirc: the resolution of those frames.
        #[arg(long, default_value = "160x90", value_parser = parse_resolution)]
        nirc_resolution: (u32, u32),
        /// Also write the numbers as JSON to this file (with --nirc: the neural cache's).
        #[arg(long)]
        json: Option<PathBuf>,
        #[command(flatten)]
        history: HistoryArgs,
    },
}

/// Where a run's values, intervals and verdicts are appended.
#[derive(clap::Args)]
struct HistoryArgs {
    /// Append this run's values, intervals and verdicts to the results history in DIR (one
    /// file per run; keep it in git or on a shared disk).
    #[arg(long, value_name = "DIR", default_value = tools::history::DEFAULT_DIR)]
    history: PathBuf,
    /// Do not append to the results history.
    #[arg(long, conflicts_with = "history")]
    no_history: bool,
}

impl HistoryArgs {
    /// Appends what `record` builds, unless switched off; a history that cannot be written is
    /// a warning (the run's own results are written already).
    fn append(&self, record: impl FnOnce() -> anyhow::Result<tools::history::Record>) {
        if self.no_history {
            return;
        }
        match record().and_then(|r| tools::history::append(&self.history, &r)) {
            Ok(path) => println!("history: {}", path.display()),
            Err(e) => eprintln!("warning: results history not written: {e:#}"),
        }
    }

    /// `append`, then each of the record's ratios against the last kept record of the same
    /// bench, build and adapter, read against its run-to-run spread: a loss shows the day it
    /// lands.
    fn append_compared(&self, record: impl FnOnce() -> anyhow::Result<tools::history::Record>) {
        if self.no_history {
            return;
        }
        let record = match record() {
            Ok(r) => r,
            Err(e) => return eprintln!("warning: results history not written: {e:#}"),
        };
        let before = tools::history::read(&self.history);
        self.append(|| Ok(record.clone()));
        match before {
            Ok(h) => {
                let h: Vec<_> = h.into_iter().map(|(_, r)| r).collect();
                let changes = tools::history::series::against_last(&h, &record);
                print!("{}", tools::history::series::changes_markdown(&changes));
            }
            Err(e) => eprintln!("warning: results history not read: {e:#}"),
        }
    }
}

#[derive(Subcommand)]
enum GalleryPage {
    /// Play each method's failure case and write the failure-cases page and its pictures.
    Failures(GalleryArgs),
    /// Play the showcase and write the speed-accuracy page's charts and numbers.
    Speed(GalleryArgs),
}

#[derive(clap::Args)]
struct GalleryArgs {
    /// The page: only its part between `<!-- generated: flicker gallery MODE -->` and
    /// `<!-- end generated -->` is written (a missing page is created).
    #[arg(long)]
    out: PathBuf,
    /// Where the pictures go [default: images/failures or images/speed-accuracy beside the page].
    #[arg(long)]
    images: Option<PathBuf>,
    /// Where the runs go.
    #[arg(long, default_value = "runs/gallery")]
    runs: PathBuf,
    /// Only this failure case (its name on the page).
    #[arg(long)]
    only: Option<String>,
    /// Recorded frames of every run (overrides each case's own).
    #[arg(long)]
    frames: Option<u32>,
    /// Image size of every run as WIDTHxHEIGHT (overrides each case's own).
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Cache folder for references [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
    #[arg(long)]
    cache_dir: Option<PathBuf>,
    /// Do not draw progress bars.
    #[arg(long)]
    quiet: bool,
}

impl GalleryArgs {
    fn options(self) -> tools::gallery::GalleryOptions {
        tools::gallery::GalleryOptions {
            page: self.out,
            images: self.images,
            runs: self.runs,
            root: PathBuf::from("."),
            only: self.only,
            resolution: self.resolution,
            frames: self.frames,
            cache_dir: self.cache_dir,
            progress: !self.quiet,
        }
    }
}

#[derive(Subcommand)]
enum SuiteAction {
    /// Play the suite and judge its gates; exit code 0 when all pass, 1 when one fails, 2 when
    /// the suite could not be played (bad file, missing baseline).
    Run(SuiteArgs),
    /// Play the suite and record its measurements as this adapter's baseline.
    Bless(SuiteArgs),
}

#[derive(clap::Args)]
struct SuiteArgs {
    /// The suite file (RON), e.g. suites/smoke.ron
    suite: PathBuf,
    /// Output folder: each case's run folders, summary.md, junit.xml [default: runs/suite_NAME].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Cache folder for references [default: $FLICKER_CACHE_DIR or ~/.cache/flicker].
    #[arg(long)]
    cache_dir: Option<PathBuf>,
    /// Baseline file [default: baselines/NAME.json next to the suite file].
    #[arg(long)]
    baselines: Option<PathBuf>,
    /// Do not draw progress bars.
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    history: HistoryArgs,
}

impl SuiteArgs {
    fn options(&self) -> tools::suite::SuiteOptions {
        tools::suite::SuiteOptions {
            suite: self.suite.clone(),
            out: self.out.clone(),
            cache_dir: self.cache_dir.clone(),
            baselines: self.baselines.clone(),
            progress: !self.quiet,
        }
    }
}

/// `flicker suite`: its own exit codes (1 = a gate failed, 2 = could not run).
fn suite(action: SuiteAction) -> ExitCode {
    let result = match action {
        SuiteAction::Run(args) => tools::suite::run(&args.options()).map(|outcome| {
            print!("{}", outcome.markdown);
            println!("\nwrote {} and {}", outcome.summary.display(), outcome.junit.display());
            args.history.append(|| tools::history::suite_record(&outcome, &args.suite));
            outcome.passed()
        }),
        SuiteAction::Bless(args) => tools::suite::bless(&args.options()).map(|file| {
            println!("wrote {}", file.display());
            true
        }),
    };
    exit_code(result)
}

#[derive(Subcommand)]
enum SweepAction {
    /// Plan, run every job on this machine and merge: `flicker sweep run SWEEP.ron --out DIR`.
    Run {
        /// The sweep file (RON), e.g. sweeps/nirc_kappa.ron
        sweep: PathBuf,
        /// The sweep's folder: plan.json, runs/, done/, logs/, summary.json, chart, report.md.
        #[arg(long)]
        out: PathBuf,
        /// Jobs at a time [default: the number of cores].
        #[arg(long)]
        jobs: Option<usize>,
        /// Reference cache of the jobs [default: DIR/cache].
        #[arg(long)]
        cache_dir: Option<PathBuf>,
    },
    /// Write the job list DIR/plan.json (deterministic), DIR/jobs.txt (GNU parallel) and
    /// DIR/sweep.sbatch (Slurm array, task i = job i).
    Plan {
        /// The sweep file (RON).
        sweep: PathBuf,
        /// The sweep's folder.
        #[arg(long)]
        out: PathBuf,
        /// Reference cache of the jobs [default: DIR/cache].
        #[arg(long)]
        cache_dir: Option<PathBuf>,
    },
    /// Run one job of a planned sweep (what every executor runs; reruns a failed job alone).
    Job {
        /// The sweep's folder.
        dir: PathBuf,
        /// The job's index in DIR/plan.json.
        #[arg(long)]
        index: usize,
        /// Do not draw the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// The `local` executor: run the planned jobs that have not finished, N at a time.
    Local {
        /// The sweep's folder.
        dir: PathBuf,
        /// Jobs at a time [default: the number of cores].
        #[arg(long)]
        jobs: Option<usize>,
        /// Run every job again, finished or not.
        #[arg(long)]
        again: bool,
    },
    /// Gather the finished jobs into DIR/summary.json, the speed-vs-accuracy chart and DIR/report.md.
    Merge {
        /// The sweep's folder.
        dir: PathBuf,
    },
}

/// `flicker sweep`: exit code 1 when a job failed, 2 when the sweep could not be run.
fn sweep(action: SweepAction) -> ExitCode {
    use tools::sweep;
    let cores = || std::thread::available_parallelism().map_or(1, |n| n.get());
    let result = (|| -> anyhow::Result<bool> {
        let exe = std::env::current_exe()?;
        let local = |dir: &std::path::Path,
                     jobs: Option<usize>,
                     again: bool|
         -> anyhow::Result<bool> {
            let outcome = sweep::run_local(dir, &exe, jobs.unwrap_or_else(cores), again)?;
            if !outcome.failed.is_empty() {
                let list =
                    outcome.failed.iter().map(usize::to_string).collect::<Vec<_>>().join(", ");
                eprintln!(
                    "error: jobs {list} failed (logs in {}/logs/); rerun them with `flicker sweep local {}`",
                    dir.display(),
                    dir.display()
                );
            }
            Ok(outcome.failed.is_empty())
        };
        let merged = |dir: &std::path::Path| -> anyhow::Result<()> {
            let m = sweep::merge(dir)?;
            println!(
                "wrote {}, {} and {}",
                m.summary_file.display(),
                m.chart.display(),
                m.report.display()
            );
            Ok(())
        };
        match action {
            SweepAction::Plan { sweep, out, cache_dir } => {
                let plan = sweep::plan(&sweep, &out, cache_dir, &exe)?;
                println!("planned {} jobs in {}", plan.jobs.len(), out.display());
                Ok(true)
            }
            SweepAction::Job { dir, index, quiet } => {
                let record = sweep::run_job(&dir, index, !quiet)?;
                println!("job {index} done in {:.1} s", record.wall_s);
                Ok(true)
            }
            SweepAction::Local { dir, jobs, again } => local(&dir, jobs, again),
            SweepAction::Merge { dir } => merged(&dir).map(|_| true),
            SweepAction::Run { sweep, out, jobs, cache_dir } => {
                let plan = sweep::plan(&sweep, &out, cache_dir, &exe)?;
                println!("planned {} jobs in {}", plan.jobs.len(), out.display());
                if !local(&out, jobs, false)? {
                    return Ok(false);
                }
                merged(&out).map(|_| true)
            }
        }
    })();
    exit_code(result)
}

/// 0 when it passed, 1 when it ran and failed (a gate, a job), 2 when it could not run, 130 when a
/// signal stopped it.
fn exit_code(result: anyhow::Result<bool>) -> ExitCode {
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) if e.is::<playback::interrupt::Interrupted>() => {
            eprintln!("{e}");
            ExitCode::from(playback::interrupt::EXIT_CODE)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 160x90, got '{s}'"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected WIDTHxHEIGHT such as 160x90, got '{s}'"))
    };
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 {
        return Err(format!("width and height must be at least 1, got '{s}'"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    runtime_dir::ensure();
    let cli = Cli::parse();
    // The commands that play runs stop between frames on SIGINT/SIGTERM; the others end at once.
    let plays = matches!(
        cli.command,
        Command::Run { .. }
            | Command::Gallery { .. }
            | Command::Suite { .. }
            | Command::Reproduce { .. }
            | Command::Sweep { action: SweepAction::Job { .. } }
    );
    if plays && let Err(e) = playback::interrupt::install() {
        eprintln!("error: cannot catch SIGINT/SIGTERM: {e:#}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Suite { action } => return suite(action),
        Command::Sweep { action } => return sweep(action),
        Command::Reproduce {
            paper,
            scale,
            seeds,
            out,
            claims,
            cache_dir,
            quiet,
            plan,
            judge_from,
            history,
        } => {
            let opts = tools::reproduce::ReproduceOptions {
                paper,
                claims_dir: claims,
                scale,
                seeds,
                out,
                cache_dir,
                progress: !quiet,
            };
            use tools::reproduce::distributed;
            match (plan, judge_from) {
                (Some(dir), _) => std::env::current_exe()
                    .map_err(anyhow::Error::from)
                    .and_then(|exe| distributed::plan(&opts, &dir, &exe))
                    .map(|(plan, _)| {
                        let (n, d) = (plan.jobs.len(), dir.display());
                        println!(
                            "planned {n} jobs in {d}; run them with `flicker sweep local {d}`, `parallel < {d}/jobs.txt` or `sbatch {d}/sweep.sbatch`, then judge with --judge-from {d}"
                        );
                    }),
                (None, judged) => {
                    let outcome = match &judged {
                        Some(dir) => distributed::judge_from(&opts, dir),
                        None => tools::reproduce::reproduce(&opts),
                    };
                    outcome.map(|outcome| {
                        print!("{}", outcome.markdown);
                        println!("\nwrote {}", outcome.folder.join("reproduce.md").display());
                        history.append(|| {
                            tools::history::reproduce_record(
                                &outcome,
                                &opts.claims_dir,
                                &opts.paper,
                                opts.scale.name(),
                            )
                        });
                    })
                }
            }
        }
        Command::History { history, out, only, fail_on_change } => {
            let opts = tools::history::ShowOptions { history, out, filter: only };
            return exit_code(tools::history::show(&opts).map(|shown| {
                print!("{}", shown.markdown);
                println!(
                    "\nwrote {} and {} charts in {}",
                    shown.report.display(),
                    shown.charts.len(),
                    opts.out.join("charts").display()
                );
                let flagged = shown.flagged_now();
                for s in &flagged {
                    let what: Vec<String> = s.latest_flags().iter().map(|f| f.describe()).collect();
                    eprintln!("changed at the latest commit: {}: {}", s.key.id, what.join("; "));
                }
                !fail_on_change || flagged.is_empty()
            }));
        }
        Command::Run { scenario, resume, frames, resolution, spp, seed, out, cache_dir, quiet } => {
            let played = match (resume, scenario) {
                (Some(run), _) => playback::resume::resume(&run, cache_dir, !quiet),
                (None, scenario) => play::run(&RunOptions {
                    scenario: scenario.unwrap_or_default(),
                    overrides: Overrides { frames, resolution, spp, seed, out },
                    cache_dir,
                    progress: !quiet,
                }),
            };
            played.map(|summary| {
                if summary.records.is_empty() {
                    // A resumed run whose frames were all written: only its report was.
                    println!("wrote the summary of {}", summary.folder.display());
                } else {
                    println!(
                        "wrote {} ({} frames; references: {} rendered, {} from cache)",
                        summary.folder.display(),
                        summary.records.len(),
                        summary.references_rendered,
                        summary.references_cached
                    );
                }
                println!("report: {}", summary.report.display());
            })
        }
        Command::Gallery { page } => {
            let written = match page {
                GalleryPage::Failures(args) => tools::gallery::failures(&args.options()),
                GalleryPage::Speed(args) => tools::gallery::speed(&args.options()),
            };
            written.map(|page| println!("wrote {}", page.display()))
        }
        Command::Schedule { scenario } => {
            playback::scenario::RunSpec::load(&scenario, &Overrides::default())
                .and_then(|spec| playback::methods::describe_schedule(&spec.methods))
                .map(|text| print!("{text}"))
        }
        Command::Scenes => {
            print!("{}", sim::scenes::listing());
            Ok(())
        }
        Command::Compare(args) => metrics::compare(&args.options()),
        Command::Export(args) => tools::export::export(&args.options())
            .map(|manifest| println!("wrote {}", manifest.display())),
        Command::Measure(args) => args
            .options()
            .and_then(|o| tools::measure::measure(&o))
            .map(|path| println!("wrote {}", path.display())),
        Command::Report(args) => {
            report::report(&args.options()).map(|path| println!("wrote {}", path.display()))
        }
        Command::Bench {
            out,
            repeats,
            nirc: true,
            nirc_batch,
            nirc_queries,
            nirc_frames,
            nirc_resolution,
            json,
            ..
        } => bench::command::nirc(
            out,
            json,
            nirc_batch,
            nirc_queries,
            repeats,
            nirc_frames,
            nirc_resolution,
        ),
        Command::Bench { out, json, memory: true, .. } => bench::command::memory(out, json),
        Command::Bench { out, json, metrics_only: true, repeats, history, .. } => {
            bench::command::metrics(out, json, repeats).map(|(adapter, entries)| {
                history.append_compared(|| Ok(bench::command::record("metrics", &adapter, entries)))
            })
        }
        Command::Bench { out, rays, frames, no_metrics, repeats, json, history, .. } => {
            bench::command::speed(out, json, rays, frames, no_metrics, repeats).map(
                |(adapter, entries)| {
                    history
                        .append_compared(|| Ok(bench::command::record("speed", &adapter, entries)))
                },
            )
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<playback::interrupt::Interrupted>() => {
            eprintln!("{e}");
            ExitCode::from(playback::interrupt::EXIT_CODE)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
