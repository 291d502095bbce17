//! `flicker measure`: the run's metrics for frames from any renderer. Reads a reference
//! sequence and test sequences (EXR or PNG, frame numbers from file names), measures every test
//! frame as a run's Measure stage does (SMAPE against the previous frame, reprojected where
//! motion vectors are given, HDR-FLIP, MSE, relative MSE, PSNR against the reference) and writes
//! a run folder like `flicker run`: frames.csv, the frames, manifest.json, then summary.json
//! (with JOD), the charts and report.html. Every input is read and checked before anything is
//! written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use frame::frame_metrics::{Frame, error_vs_reference, smape_vs_previous};
use frame::frame_record::FrameRecord;
use frame::output;
use frame::run_folder::{MOTION, RunFolder};
use metrics::frames_csv::{self, Cell};
use metrics::{CvvdpSettings, Image, load_image};
use serde_json::json;

/// What to measure and where to write it.
#[derive(Clone, Debug)]
pub struct MeasureOptions {
    pub reference: PathBuf,
    /// (name, folder) of each test sequence; the name labels it in frames.csv and the report.
    pub tests: Vec<(String, PathBuf)>,
    /// (test name, folder) of motion vectors (EXR, R and G: pixels from a frame to the previous).
    pub motion: Vec<(String, PathBuf)>,
    /// (test name, CSV file) of per-frame times ([`Timings`]): the test's frames.csv rows get
    /// `wall_ms_total` and its passes, and it joins the speed-against-accuracy charts.
    pub timings: Vec<(String, PathBuf)>,
    pub fps: f64,
    /// Frames of events (the input's frame numbers), for the summary's windows.
    pub events: Vec<u32>,
    /// A label per event (e.g. a package's "toggle 'lamp'"); empty: "input frame N".
    pub labels: Vec<String>,
    pub out: PathBuf,
    pub cvvdp: CvvdpSettings,
    pub smape_epsilon: f32,
}

/// A sequence on disk: its frame files by frame number, consecutive.
#[derive(Clone, Debug)]
pub struct Sequence {
    pub dir: PathBuf,
    pub frames: Vec<(u32, PathBuf)>,
}

/// The last run of digits in a file's stem: `frame_0012.exr` is frame 12.
fn frame_number(path: &Path) -> Option<u32> {
    let stem = path.file_stem()?.to_str()?;
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end].rfind(|c: char| !c.is_ascii_digit()).map_or(0, |i| i + 1);
    stem[start..end].parse().ok()
}

impl Sequence {
    /// The EXR and PNG files of `dir` (other files are ignored), by frame number; where a frame
    /// has both (a flicker run's frames), the EXR. Refuses a folder without images, an image
    /// without a number, two images of one kind for one frame and a gap.
    pub fn read(dir: &Path) -> anyhow::Result<Self> {
        let entries = std::fs::read_dir(dir)
            .with_context(|| format!("{}: cannot read the folder", dir.display()))?;
        let mut by_number: BTreeMap<u32, PathBuf> = BTreeMap::new();
        for e in entries {
            let path =
                e.with_context(|| format!("{}: cannot list the folder", dir.display()))?.path();
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
            if !path.is_file() || (ext != "exr" && ext != "png") {
                continue;
            }
            let Some(n) = frame_number(&path) else {
                bail!(
                    "{}: no frame number in the file name; expected e.g. 0007.{ext}",
                    path.display()
                )
            };
            match by_number.get(&n) {
                Some(other) if other.extension() == path.extension() => {
                    bail!("{} and {}: two images of frame {n}", other.display(), path.display())
                }
                // The EXR holds the radiance, the PNG only its tone-mapped picture.
                Some(_) if ext == "png" => {}
                _ => {
                    by_number.insert(n, path.clone());
                }
            }
        }
        let (Some((&first, _)), Some((&last, _))) =
            (by_number.first_key_value(), by_number.last_key_value())
        else {
            bail!("{}: no .exr or .png frames", dir.display())
        };
        if let Some(missing) = (first..=last).find(|n| !by_number.contains_key(n)) {
            bail!("{}: frame {missing} is missing (frames {first}..={last})", dir.display());
        }
        Ok(Self { dir: dir.to_path_buf(), frames: by_number.into_iter().collect() })
    }

    fn numbers(&self) -> Vec<u32> {
        self.frames.iter().map(|f| f.0).collect()
    }
}

/// One frame of a sequence, checked: readable, of the reference's size, finite.
fn load_checked(path: &Path, frame: u32, size: Option<(u32, u32)>) -> anyhow::Result<Image> {
    let img = load_image(path).with_context(|| format!("frame {frame}"))?;
    if let Some((w, h)) = size
        && (img.width, img.height) != (w, h)
    {
        bail!(
            "{}: frame {frame} is {}x{}; expected {w}x{h} like the reference",
            path.display(),
            img.width,
            img.height
        );
    }
    if let Some(i) = img.rgb.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        bail!(
            "{}: frame {frame} has a non-finite value at pixel ({}, {}); expected finite radiance",
            path.display(),
            i as u32 % img.width,
            i as u32 / img.width
        );
    }
    Ok(img)
}

fn load_motion(path: &Path, frame: u32, (w, h): (u32, u32)) -> anyhow::Result<Vec<[f32; 2]>> {
    let (mw, mh, rgba) = output::read_exr(path).with_context(|| format!("frame {frame}"))?;
    if (mw, mh) != (w, h) {
        bail!(
            "{}: frame {frame} is {mw}x{mh}; expected {w}x{h} like the reference",
            path.display()
        );
    }
    if rgba.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
        bail!("{}: frame {frame} has a non-finite motion vector", path.display());
    }
    Ok(rgba.iter().map(|p| [p[0], p[1]]).collect())
}

/// A test's per-frame times from a CSV file: a header `frame,ms` and optionally one column per
/// pass (`frame,ms,trace,denoise`), then one row per frame (the input's frame numbers) in
/// milliseconds. Passes that add up to less than `ms` leave the rest as a pass `other`.
#[derive(Clone, Debug, PartialEq)]
pub struct Timings {
    pub file: PathBuf,
    pub passes: Vec<String>,
    /// By frame number: the frame's total and each pass's time.
    pub rows: BTreeMap<u32, (f64, Vec<f64>)>,
}

impl Timings {
    /// Reads and checks `file`: every frame of `numbers` once, no other frame, every time a
    /// finite number >= 0; errors name the file and line or frame.
    pub fn read(file: &Path, numbers: &[u32]) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(file)
            .with_context(|| format!("{}: cannot read the timings", file.display()))?;
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
        let Some((_, header)) = lines.next() else {
            bail!("{}: empty; expected a header `frame,ms` and a row per frame", file.display())
        };
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        if columns.len() < 2 || columns[0] != "frame" || columns[1] != "ms" {
            bail!(
                "{}:1: header `{header}`; expected `frame,ms` then optional pass columns",
                file.display()
            );
        }
        let passes: Vec<String> = columns[2..].iter().map(|c| c.to_string()).collect();
        let mut rows = BTreeMap::new();
        for (i, line) in lines {
            let at = format!("{}:{}", file.display(), i + 1);
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != columns.len() {
                bail!("{at}: {} cells; expected {} like the header", cells.len(), columns.len());
            }
            let frame: u32 = cells[0].parse().map_err(|_| {
                anyhow::anyhow!("{at}: frame `{}`; expected a frame number", cells[0])
            })?;
            let mut ms = Vec::new();
            for (c, cell) in cells[1..].iter().enumerate() {
                match cell.parse::<f64>() {
                    Ok(v) if v.is_finite() && v >= 0.0 => ms.push(v),
                    _ => bail!(
                        "{at}: frame {frame}: {} `{cell}`; expected milliseconds (a finite number >= 0)",
                        columns[c + 1]
                    ),
                }
            }
            if !numbers.contains(&frame) {
                bail!("{at}: frame {frame} has no reference frame");
            }
            let total = ms.remove(0);
            if ms.iter().sum::<f64>() > total * (1.0 + 1e-9) + 1e-9 {
                bail!("{at}: frame {frame}: its passes add up to more than its ms {total}");
            }
            if rows.insert(frame, (total, ms)).is_some() {
                bail!("{at}: frame {frame} a second time; expected one row per frame");
            }
        }
        if let Some(n) = numbers.iter().find(|n| !rows.contains_key(n)) {
            bail!(
                "{}: frame {n} is missing ({} rows for {} frames); expected one row per reference frame",
                file.display(),
                rows.len(),
                numbers.len()
            );
        }
        Ok(Self { file: file.to_path_buf(), passes, rows })
    }

    /// The frame's passes for frames.csv: the named ones and `other` (the rest of its total), or
    /// a single pass `frame` when the file has no breakdown.
    fn passes_of(&self, frame: u32) -> Vec<(String, Option<f64>)> {
        let (total, ms) = &self.rows[&frame];
        if self.passes.is_empty() {
            return vec![("frame".into(), Some(*total))];
        }
        let mut out: Vec<(String, Option<f64>)> =
            self.passes.iter().cloned().zip(ms.iter().map(|v| Some(*v))).collect();
        out.push(("other".into(), Some((total - ms.iter().sum::<f64>()).max(0.0))));
        out
    }
}

/// The inputs, read and checked: every sequence has the reference's frame numbers.
struct Inputs {
    reference: Sequence,
    tests: Vec<(String, Sequence, Option<Sequence>)>,
    /// Per test (in `tests`' order), its times.
    timings: Vec<Option<Timings>>,
}

fn check_options(opts: &MeasureOptions) -> anyhow::Result<Inputs> {
    if opts.tests.is_empty() {
        bail!("no --test NAME=DIR; expected at least one test sequence");
    }
    if !(opts.fps.is_finite() && opts.fps > 0.0) {
        bail!("--fps {}; expected a positive frame rate", opts.fps);
    }
    if let Some(p) = opts.cvvdp.problem() {
        bail!("--display/--exposure: {p}");
    }
    let reference = Sequence::read(&opts.reference)?;
    let numbers = reference.numbers();
    let mut tests: Vec<(String, Sequence, Option<Sequence>)> = Vec::new();
    for (name, dir) in &opts.tests {
        if name.is_empty() || name.contains(['/', '\\', ',']) || name == "reference" {
            bail!(
                "--test {name}={}: expected a name without '/', '\\' or ',' (not 'reference')",
                dir.display()
            );
        }
        if tests.iter().any(|(n, ..)| n == name) {
            bail!("--test {name}: two test sequences of one name");
        }
        let seq = Sequence::read(dir)?;
        same_frames(&seq, &numbers, &reference.dir)?;
        tests.push((name.clone(), seq, None));
    }
    for (name, dir) in &opts.motion {
        let Some(t) = tests.iter_mut().find(|(n, ..)| n == name) else {
            bail!("--motion {name}={}: no --test named {name}", dir.display());
        };
        let seq = Sequence::read(dir)?;
        same_frames(&seq, &numbers, &reference.dir)?;
        t.2 = Some(seq);
    }
    let mut timings: Vec<Option<Timings>> = vec![None; tests.len()];
    for (name, file) in &opts.timings {
        let Some(i) = tests.iter().position(|(n, ..)| n == name) else {
            bail!("--timings {name}={}: no --test named {name}", file.display());
        };
        if timings[i].is_some() {
            bail!("--timings {name}: two timing files for one test");
        }
        timings[i] = Some(Timings::read(file, &numbers)?);
    }
    let (first, last) = (numbers[0], numbers[numbers.len() - 1]);
    if let Some(e) = opts.events.iter().find(|&&e| e < first || e > last) {
        bail!("--events: frame {e} is outside the sequences' frames {first}..={last}");
    }
    Ok(Inputs { reference, tests, timings })
}

fn same_frames(seq: &Sequence, numbers: &[u32], reference: &Path) -> anyhow::Result<()> {
    let got = seq.numbers();
    if let Some(n) = numbers.iter().find(|n| !got.contains(n)) {
        bail!(
            "{}: frame {n} is missing (the reference {} has it)",
            seq.dir.display(),
            reference.display()
        );
    }
    if let Some(n) = got.iter().find(|n| !numbers.contains(n)) {
        bail!("{}: frame {n} has no reference frame in {}", seq.dir.display(), reference.display());
    }
    Ok(())
}

/// Reads every frame once, checks it and measures it; the records of all frames (frames
/// renumbered from 0), and the image size.
fn measure_all(inputs: &Inputs, eps: f32) -> anyhow::Result<(Vec<FrameRecord>, (u32, u32))> {
    let mut size = None;
    let mut previous: Vec<Option<Frame>> = vec![None; inputs.tests.len()];
    let mut records = Vec::new();
    for (k, (n, ref_path)) in inputs.reference.frames.iter().enumerate() {
        let reference = Frame { image: load_checked(ref_path, *n, size)?, motion: None };
        let wh = *size.get_or_insert((reference.image.width, reference.image.height));
        for (i, (name, seq, motion)) in inputs.tests.iter().enumerate() {
            let image = load_checked(&seq.frames[k].1, *n, Some(wh))?;
            let motion = match motion {
                Some(m) => Some(load_motion(&m.frames[k].1, *n, wh)?),
                None => None,
            };
            let current = Frame { image, motion };
            let mut rec =
                FrameRecord { method: name.clone(), frame: k as u32, ..Default::default() };
            if let Some(t) = &inputs.timings[i] {
                rec.passes = t.passes_of(*n);
                // Another renderer's own clock: frames.csv's wall_ms columns.
                rec.clock = Some(render::timing::Clock::Wall);
            }
            smape_vs_previous(&mut rec, &current, previous[i].as_ref(), eps);
            error_vs_reference(&mut rec, &current, Some(&reference));
            records.push(rec);
            previous[i] = Some(current);
        }
    }
    Ok((records, size.unwrap_or((0, 0))))
}

fn rgba(img: &Image) -> Vec<[f32; 4]> {
    img.rgb.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect()
}

fn write_frame(path_exr: &Path, path_png: &Path, img: &Image) -> anyhow::Result<()> {
    let px = rgba(img);
    output::write_exr(path_exr, img.width, img.height, &px)?;
    output::write_png(path_png, img.width, img.height, &px, 1.0)
}

/// frames.csv with the `cpu_ms` cells empty: frames from elsewhere come without flicker's CPU
/// cost, and a column of zeros would draw speed charts and mark a "fastest" method (their own
/// times, given with --timings, are in the wall_ms columns).
fn without_times(records: &[FrameRecord]) -> String {
    let (columns, mut cells) = frame::frame_record::table(records);
    if let Some(col) = columns.iter().position(|c| c == "cpu_ms") {
        for row in &mut cells {
            row[col] = Cell::Empty;
        }
    }
    let rows = records.iter().zip(cells).map(|(r, c)| (r.method.as_str(), r.frame, c));
    frames_csv::write(&columns, rows)
}

/// Sequences read, checked and measured, nothing written yet: what `flicker measure` and a
/// suite's measured case hold between checking every input and writing any run folder.
pub struct Measured {
    inputs: Inputs,
    records: Vec<FrameRecord>,
    size: (u32, u32),
}

impl Measured {
    /// Reads and checks every input and measures every frame; writes nothing.
    pub fn read(opts: &MeasureOptions) -> anyhow::Result<Self> {
        let inputs = check_options(opts)?;
        let (records, size) = measure_all(&inputs, opts.smape_epsilon)?;
        Ok(Self { inputs, records, size })
    }

    /// Every test frame's record (frames renumbered from 0).
    pub fn records(&self) -> &[FrameRecord] {
        &self.records
    }

    pub fn frames(&self) -> u32 {
        self.inputs.reference.frames.len() as u32
    }

    /// The input's first frame number: frame 0 of the run folder.
    pub fn first_frame(&self) -> u32 {
        self.inputs.reference.frames[0].0
    }

    /// Writes the run folder `opts.out` (the options `read` was given); returns the report's path.
    pub fn write(&self, opts: &MeasureOptions) -> anyhow::Result<PathBuf> {
        let (inputs, (w, h)) = (&self.inputs, self.size);
        let first = self.first_frame();
        let folder = RunFolder::new(&opts.out);
        folder.prepare()?;
        let count = self.frames();
        let names: Vec<&str> = inputs.tests.iter().map(|t| t.0.as_str()).collect();
        let manifest = json!({
            "scenario": "measure",
            "measured": {
                "reference": opts.reference.display().to_string(),
                "tests": opts.tests.iter().map(|(n, d)| json!({"name": n, "dir": d.display().to_string()})).collect::<Vec<_>>(),
                "motion": opts.motion.iter().map(|(n, d)| json!({"name": n, "dir": d.display().to_string()})).collect::<Vec<_>>(),
                "timings": opts.timings.iter().map(|(n, f)| json!({"name": n, "file": f.display().to_string()})).collect::<Vec<_>>(),
                "first_frame": first,
            },
            "flicker_version": env!("CARGO_PKG_VERSION"),
            "resolution": [w, h],
            "frames": count,
            "methods": names,
            "reference": { "frames": (0..count).collect::<Vec<_>>() },
            "events": opts.events.iter().enumerate().map(|(i, e)| json!({"frame": e - first, "label": opts.labels.get(i).cloned().unwrap_or_else(|| format!("input frame {e}"))})).collect::<Vec<_>>(),
            "regions": [],
            "settings": {
                "smape_epsilon": opts.smape_epsilon,
                "time_step": 1.0 / opts.fps,
                "cvvdp": opts.cvvdp,
                "methods": names.iter().map(|n| json!({"label": n})).collect::<Vec<_>>(),
            },
        });
        for (k, (n, path)) in inputs.reference.frames.iter().enumerate() {
            let k = k as u32;
            let img = load_checked(path, *n, Some((w, h)))?;
            write_frame(&folder.reference(k, "exr"), &folder.reference(k, "png"), &img)?;
            for (name, seq, motion) in &inputs.tests {
                let img = load_checked(&seq.frames[k as usize].1, *n, Some((w, h)))?;
                write_frame(&folder.frame(name, k, "exr"), &folder.frame(name, k, "png"), &img)?;
                if let Some(m) = motion {
                    let mv = load_motion(&m.frames[k as usize].1, *n, (w, h))?;
                    let px: Vec<[f32; 4]> = mv.iter().map(|&[x, y]| [x, y, 0.0, 1.0]).collect();
                    output::write_exr(&folder.method_image(name, MOTION, k, "exr"), w, h, &px)?;
                }
            }
        }
        output::write_text(&folder.frames_csv(), &without_times(&self.records))?;
        output::write_json(&folder.manifest(), &manifest)?;
        report::rebuild(&folder.root, &playback::methods::registry::charts())
    }
}

/// Measures the sequences and writes the run folder; returns the report's path.
pub fn measure(opts: &MeasureOptions) -> anyhow::Result<PathBuf> {
    Measured::read(opts)?.write(opts)
}

#[cfg(test)]
mod tests {
    use super::{FrameRecord, frame_number};
    use std::path::Path;

    #[test]
    fn measured_frames_have_no_times() {
        let a = FrameRecord { method: "a".into(), flip: Some(0.5), ..Default::default() };
        let csv = super::without_times(&[a]);
        let (header, row) = csv.split_once('\n').unwrap();
        assert!(header.starts_with("method,frame,cpu_ms,gpu_ms_total,"), "{header}");
        assert!(row.starts_with("a,0,,,") && row.contains(",0.500000,"), "{row}");
    }

    #[test]
    fn frame_numbers_are_the_last_digits_of_the_stem() {
        assert_eq!(frame_number(Path::new("a/0007.exr")), Some(7));
        assert_eq!(frame_number(Path::new("render2_frame_0012.png")), Some(12));
        assert_eq!(frame_number(Path::new("frame.exr")), None);
    }
}
