//! `flicker gallery`: guide pages whose pictures and numbers come from runs played by one
//! command, so they cannot go stale. `failures` plays each method's failure case
//! ([`cases::CASES`]) and writes, per case, the failing frame beside the baseline's and the
//! reference's, the window means of summary.json and the command that reproduces them; `speed`
//! plays one scenario and writes its speed-against-accuracy charts and the numbers behind them.
//! Each writes the part of its page between `<!-- generated: flicker gallery MODE -->` and
//! `<!-- end generated -->`; the rest of the page is prose kept by hand.

pub mod cases;
pub mod picture;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use playback::play::{self, Overrides, RunOptions};
use serde_json::Value;

pub use cases::{CASES, Case};

/// The scenario, size and run folder of the speed page.
pub const SPEED_SCENARIO: &str = "scenarios/showcase.ron";
pub const SPEED_RESOLUTION: (u32, u32) = (64, 36);
pub const SPEED_FRAMES: u32 = 20;
/// The charts the speed page shows (report::charts' speed_vs_*).
pub const SPEED_CHARTS: [&str; 2] = ["speed_vs_flip", "speed_vs_smape"];

/// What `flicker gallery` is asked.
#[derive(Clone, Debug)]
pub struct GalleryOptions {
    /// The page written (its generated part; the page is created when missing).
    pub page: PathBuf,
    /// Where pictures go [default: images/failures or images/speed-accuracy beside the page].
    pub images: Option<PathBuf>,
    /// Where the runs go (one folder per case).
    pub runs: PathBuf,
    /// The repository root: scenarios are read from it and the commit is its checkout's.
    pub root: PathBuf,
    /// Only this case (failures).
    pub only: Option<String>,
    /// Overrides of each case's own size.
    pub resolution: Option<(u32, u32)>,
    pub frames: Option<u32>,
    pub cache_dir: Option<PathBuf>,
    pub progress: bool,
}

/// A number as the pages print it: four significant digits.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.decimals$}")
}

/// A played run read back: its folder, summary.json and manifest.json.
pub struct PlayedRun {
    pub folder: PathBuf,
    pub summary: Value,
    pub manifest: Value,
    /// The command that plays it again, as the page prints it.
    pub command: String,
}

impl PlayedRun {
    /// `method`'s mean of `column` over `window` in summary.json (`jod` reads the JOD).
    pub fn mean(&self, method: &str, window: &str, column: &str) -> Option<f64> {
        let m = self.summary["methods"]
            .as_array()?
            .iter()
            .find(|m| m["method"].as_str() == Some(method))?;
        if column == "jod" {
            return m["jod"][window].as_f64();
        }
        m["means"][window][column].as_f64()
    }

    /// The windows of summary.json: name, first and last frame, the event's label.
    pub fn windows(&self) -> Vec<(String, u64, u64, Option<String>)> {
        let Some(ws) = self.summary["windows"].as_array() else { return vec![] };
        ws.iter()
            .map(|w| {
                (
                    w["name"].as_str().unwrap_or_default().to_string(),
                    w["first"].as_u64().unwrap_or_default(),
                    w["last"].as_u64().unwrap_or_default(),
                    w["event"].as_str().map(String::from),
                )
            })
            .collect()
    }

    /// The methods of summary.json, in its order.
    pub fn methods(&self) -> Vec<String> {
        self.summary["methods"]
            .as_array()
            .map(|ms| ms.iter().filter_map(|m| m["method"].as_str().map(String::from)).collect())
            .unwrap_or_default()
    }

    /// The adapter the run played on, as manifest.json names it.
    pub fn adapter(&self) -> String {
        let a = &self.manifest["adapter"];
        let field = |k: &str| a[k].as_str().unwrap_or_default().to_string();
        format!(
            "{} ({}, {} {})",
            field("name"),
            field("backend"),
            field("driver"),
            field("driver_info")
        )
    }

    /// `method`'s values of `columns` at `frame`, from frames.csv (`None` where the row leaves a
    /// column empty or has none).
    pub fn at_frame(&self, method: &str, frame: u32, columns: &[&str]) -> Result<Vec<Option<f64>>> {
        let path = self.folder.join("frames.csv");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
        let frame = frame.to_string();
        let row: Vec<&str> = lines
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|r| r.first() == Some(&method) && r.get(1) == Some(&frame.as_str()))
            .unwrap_or_default();
        Ok(columns
            .iter()
            .map(|c| {
                let i = header.iter().position(|h| h == c)?;
                row.get(i)?.parse().ok()
            })
            .collect())
    }

    /// The frames with a reference PNG.
    fn reference_frames(&self) -> Vec<u32> {
        let mut out: Vec<u32> = std::fs::read_dir(self.folder.join("reference"))
            .into_iter()
            .flatten()
            .filter_map(|e| {
                let p = e.ok()?.path();
                (p.extension()? == "png").then(|| p.file_stem()?.to_str()?.parse().ok())?
            })
            .collect();
        out.sort();
        out
    }
}

/// Plays `scenario` at the given size into `out`, and reads it back.
fn play(
    opts: &GalleryOptions,
    scenario: &str,
    (w, h): (u32, u32),
    frames: u32,
    out: PathBuf,
) -> Result<PlayedRun> {
    let played = play::run(&RunOptions {
        scenario: opts.root.join(scenario),
        overrides: Overrides {
            frames: Some(frames),
            resolution: Some((w, h)),
            spp: None,
            seed: None,
            out: Some(out.clone()),
        },
        cache_dir: opts.cache_dir.clone(),
        progress: opts.progress,
    })
    .with_context(|| format!("playing {scenario}"))?;
    let read = |name: &str| -> Result<Value> {
        let path = played.folder.join(name);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
    };
    Ok(PlayedRun {
        summary: read("summary.json")?,
        manifest: read("manifest.json")?,
        command: format!(
            "flicker run {scenario} --frames {frames} --resolution {w}x{h} --out {}",
            out.display()
        ),
        folder: played.folder,
    })
}

/// Where the generated part of a page starts and ends.
fn markers(mode: &str) -> (String, &'static str) {
    (format!("<!-- generated: flicker gallery {mode} -->"), "<!-- end generated -->")
}

/// `generated` written between the page's markers (the page is created, titled `title`, when
/// it does not exist; one without the markers is an error rather than overwritten).
fn write_generated(page: &Path, mode: &str, title: &str, generated: &str) -> Result<()> {
    let (start, end) = markers(mode);
    let section = format!("{start}\n{}\n{end}", generated.trim_end());
    let text = match std::fs::read_to_string(page) {
        Ok(old) => {
            let (Some(a), Some(b)) = (old.find(&start), old.find(end)) else {
                bail!(
                    "{}: expected the markers `{start}` and `{end}` around the generated part",
                    page.display()
                );
            };
            format!("{}{section}{}", &old[..a], &old[b + end.len()..])
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => format!("# {title}\n\n{section}\n"),
        Err(e) => return Err(e).with_context(|| format!("reading {}", page.display())),
    };
    if let Some(dir) = page.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    frame::output::write_text(page, &text)
}

/// `path` as the page links it: relative to the page's folder where it lies under it.
fn link(page: &Path, path: &Path) -> String {
    let dir = page.parent().unwrap_or(Path::new(""));
    path.strip_prefix(dir).unwrap_or(path).display().to_string()
}

/// The line that says where the page's numbers were made (`commit`: the checkout's when the
/// command started).
fn stamp(commit: &str, command: &str, adapter: &str, wall: f64) -> String {
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "Generated by `{command}` at commit {commit}, {profile} build, adapter {adapter}, {cores} cores, {wall:.0} s wall."
    )
}

/// The table of `methods`' window means of `columns` (and JOD) in `run`'s summary.json, and
/// their values at the pictured `frame` (frames.csv's) where there is one.
pub fn window_table(
    run: &PlayedRun,
    methods: &[&str],
    columns: &[&str],
    frame: Option<u32>,
) -> Result<String> {
    let mut out = format!("| window | frames | method | {} | JOD |\n", columns.join(" | "));
    out.push_str(&format!("|---|---|---|{}---|\n", "---|".repeat(columns.len())));
    for (name, first, last, event) in run.windows() {
        let what = match event {
            Some(e) => format!("{name} ({e})"),
            None => name.clone(),
        };
        for m in methods {
            let cells: Vec<String> = columns
                .iter()
                .chain(["jod"].iter())
                .map(|c| run.mean(m, &name, c).map_or("—".into(), number))
                .collect();
            let _ = writeln!(out, "| {what} | {first}–{last} | `{m}` | {} |", cells.join(" | "));
        }
    }
    if let Some(f) = frame {
        for m in methods {
            let cells: Vec<String> = run
                .at_frame(m, f, columns)?
                .into_iter()
                .map(|v| v.map_or("—".into(), number))
                .collect();
            let _ = writeln!(
                out,
                "| frame {f} (pictured; frames.csv) | {f} | `{m}` | {} | — |",
                cells.join(" | ")
            );
        }
    }
    Ok(out)
}

/// `flicker gallery failures`: plays each case and writes the failure-cases page.
pub fn failures(opts: &GalleryOptions) -> Result<PathBuf> {
    let start = Instant::now();
    let commit = playback::manifest::commit(&opts.root.join("Cargo.toml"));
    let cases: Vec<&Case> = match &opts.only {
        Some(name) => match CASES.iter().find(|c| c.name == name) {
            Some(c) => vec![c],
            None => bail!(
                "no failure case `{name}`; expected one of {}",
                CASES.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
            ),
        },
        None => CASES.iter().collect(),
    };
    let page_dir = opts.page.parent().unwrap_or(Path::new("")).to_path_buf();
    let images = opts.images.clone().unwrap_or_else(|| page_dir.join("images/failures"));
    let (mut body, mut adapter) = (String::new(), String::new());
    let mut contents = String::new();
    for case in cases {
        let frames = opts.frames.unwrap_or(case.frames);
        let resolution = opts.resolution.unwrap_or(case.resolution);
        let run = play(opts, case.scenario, resolution, frames, opts.runs.join(case.name))?;
        adapter = run.adapter();
        for m in [case.failing, case.baseline] {
            if !run.methods().iter().any(|x| x == m) {
                bail!(
                    "case {}: {} has no method `{m}`; its methods are {}",
                    case.name,
                    case.scenario,
                    run.methods().join(", ")
                );
            }
        }
        // The pictured frame: the case's, or the reference frame nearest it.
        let wanted = case.frame.min(frames.saturating_sub(1));
        let refs = run.reference_frames();
        let frame = refs.iter().copied().min_by_key(|f| f.abs_diff(wanted)).unwrap_or(wanted);
        let png = |m: &str| run.folder.join("frames").join(m).join(format!("{frame:04}.png"));
        let reference = run.folder.join("reference").join(format!("{frame:04}.png"));
        let (failing, baseline) = (png(case.failing), png(case.baseline));
        let mut panels = vec![failing.as_path(), baseline.as_path()];
        if reference.exists() {
            panels.push(&reference);
        }
        let picture = images.join(format!("{}.png", case.name));
        picture::side_by_side(&panels, &picture)?;
        let mut order = format!("`{}`, `{}`", case.failing, case.baseline);
        if reference.exists() {
            order.push_str(" and the path-traced reference");
        }
        let _ = writeln!(contents, "- [{}: {}](#{})", case.method, case.name, case.name);
        let _ = write!(
            body,
            "\n### {name}\n\n[`{method}`]({page}) in `{scenario}`: `{failing}` against `{baseline}`. {why}\n\n\
             ![{order} at frame {frame}]({pic})\n\nLeft to right: {order} at frame {frame} ({w}x{h}).\n\n{table}\n\
             Reproduce (the window rows are summary.json's means, the pictured frame's row frames.csv's values):\n\n```sh\n{command}\n```\n",
            name = case.name,
            method = case.method,
            page = case.page,
            scenario = case.scenario,
            failing = case.failing,
            baseline = case.baseline,
            why = case.why.split_whitespace().collect::<Vec<_>>().join(" "),
            pic = link(&opts.page, &picture),
            w = resolution.0,
            h = resolution.1,
            table = window_table(&run, &[case.failing, case.baseline], case.columns, Some(frame))?,
            command = run.command,
        );
    }
    let mut command = format!("flicker gallery failures --out {}", opts.page.display());
    if let Some(only) = &opts.only {
        command.push_str(&format!(" --only {only}"));
    }
    let generated = format!(
        "{}\n\n{contents}{body}",
        stamp(&commit, &command, &adapter, start.elapsed().as_secs_f64())
    );
    write_generated(&opts.page, "failures", "Failure cases", &generated)?;
    Ok(opts.page.clone())
}

/// `flicker gallery speed`: plays the showcase and writes the speed-accuracy page's charts and
/// numbers.
pub fn speed(opts: &GalleryOptions) -> Result<PathBuf> {
    let start = Instant::now();
    let commit = playback::manifest::commit(&opts.root.join("Cargo.toml"));
    let page_dir = opts.page.parent().unwrap_or(Path::new("")).to_path_buf();
    let images = opts.images.clone().unwrap_or_else(|| page_dir.join("images/speed-accuracy"));
    let frames = opts.frames.unwrap_or(SPEED_FRAMES);
    let resolution = opts.resolution.unwrap_or(SPEED_RESOLUTION);
    let run = play(opts, SPEED_SCENARIO, resolution, frames, opts.runs.join("speed_accuracy"))?;
    std::fs::create_dir_all(&images).with_context(|| format!("creating {}", images.display()))?;
    let mut pictures = String::new();
    for chart in SPEED_CHARTS {
        let from = run.folder.join("charts").join(format!("{chart}.svg"));
        let to = images.join(format!("{chart}.svg"));
        std::fs::copy(&from, &to)
            .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
        let _ = writeln!(pictures, "![{chart}]({})\n", link(&opts.page, &to));
    }
    let methods = run.methods();
    let names: Vec<&str> = methods.iter().map(String::as_str).collect();
    // The time the charts plot: GPU timestamps where the adapter has them, else the wall time
    // of the passes, else the CPU time (report::charts' order).
    let time = ["gpu_ms_total", "wall_ms_total", "cpu_ms"]
        .into_iter()
        .find(|c| names.iter().any(|m| run.mean(m, "overall", c).is_some()))
        .context("the run has no time column")?;
    // The front of each chart: the methods no other beats in both mean time and error.
    let mut fronts = format!("The charts' time axis is `{time}`.\n\n");
    for metric in ["flip", "smape"] {
        let points: Vec<(&str, (f64, f64))> = names
            .iter()
            .filter_map(|m| {
                Some((*m, (run.mean(m, "overall", time)?, run.mean(m, "overall", metric)?)))
            })
            .collect();
        let front =
            report::charts::pareto_front(&points.iter().map(|(_, p)| *p).collect::<Vec<_>>());
        let on: Vec<String> = points
            .iter()
            .filter(|(_, p)| front.contains(p))
            .map(|(m, _)| format!("`{m}`"))
            .collect();
        let _ = writeln!(fronts, "- {}: on the front: {}.", metric.to_uppercase(), on.join(", "));
    }
    let mut command = format!("flicker gallery speed --out {}", opts.page.display());
    if opts.frames.is_some() || opts.resolution.is_some() {
        command.push_str(&format!(
            " --frames {frames} --resolution {}x{}",
            resolution.0, resolution.1
        ));
    }
    let generated = format!(
        "{}\n\nThe run: `{SPEED_SCENARIO}` at {}x{}, {frames} frames. Played again by\n\n```sh\n{}\n```\n\n\
         {pictures}{fronts}\nEvery method's means per window (summary.json):\n\n{}",
        stamp(&commit, &command, &run.adapter(), start.elapsed().as_secs_f64()),
        resolution.0,
        resolution.1,
        run.command,
        window_table(&run, &names, &[time, "flip", "smape"], None)?,
    );
    write_generated(&opts.page, "speed", "Speed against accuracy", &generated)?;
    Ok(opts.page.clone())
}
