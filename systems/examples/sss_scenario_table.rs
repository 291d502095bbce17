//! Table 7.3's analogue (realtime-sss-thesis Sec. 7.4) from run folders of the SSS scenarios
//! (scenarios/sss_flash.ron, sss_toggle.ron, sss_boids.ron): per method the mean spp (frames.csv
//! `sss_mean_spp`), the SSS passes' mean ms per frame, the mean over frames of the PSNR of
//! luminance over the SSS pixels against the run's `pass_2048` method (the thesis's reference;
//! peak = its largest luminance over the run), and the mean frame-to-frame SMAPE over the SSS
//! pixels. The SSS pixels are those where `pass_2048`'s count image is non-zero. Writes the
//! Markdown table to stdout and the per-frame SMAPE of each run to RUN/sss_smape.csv.
//!
//! A folder without frames.csv but with run folders `seed*` under it is one scenario over
//! several seeds: its rows give each seed's value and the mean, and Table 7.3's relations are
//! judged on the seeds paired (one-sided 95% Student-t bounds on the per-seed differences).
//!
//! cargo run -p systems --example sss_scenario_table -- RUN...   (scripts/sss_scenario_table.sh)

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sss::evaluation::{psnr_luminance, smape_luminance};
use sss::sampling::luminance;
use statrs::distribution::{ContinuousCDF, StudentsT};
use systems::output::read_exr;
use systems::run_folder::RunFolder;

const REFERENCE: &str = "pass_2048";

/// frames.csv as (header, rows).
fn read_csv(path: &Path) -> Result<(Vec<String>, Vec<Vec<String>>)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .with_context(|| format!("{}: empty", path.display()))?
        .split(',')
        .map(str::to_string)
        .collect();
    let rows: Vec<Vec<String>> =
        lines.map(|l| l.split(',').map(str::to_string).collect()).collect();
    for (i, r) in rows.iter().enumerate() {
        if r.len() != header.len() {
            bail!(
                "{}:{}: {} fields; expected {} as in the header",
                path.display(),
                i + 2,
                r.len(),
                header.len()
            );
        }
    }
    Ok((header, rows))
}

fn luminance_image(path: &Path) -> Result<Vec<f32>> {
    Ok(read_exr(path)?.2.iter().map(|p| luminance([p[0], p[1], p[2]])).collect())
}

fn mask(path: &Path) -> Result<Vec<bool>> {
    let img =
        image::open(path).with_context(|| format!("reading {}", path.display()))?.into_luma8();
    Ok(img.pixels().map(|p| p.0[0] > 0).collect())
}

struct Row {
    method: String,
    spp: f64,
    ms: f64,
    psnr: f64,
    smape: f64,
}

fn table(run: &Path) -> Result<(Vec<Row>, String)> {
    let folder = RunFolder::new(run);
    let (header, rows) = read_csv(&folder.frames_csv())?;
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{}: no column {name}", folder.frames_csv().display()))
    };
    let (method_col, frame_col, spp_col) =
        (column("method")?, column("frame")?, column("sss_mean_spp")?);
    let pass_cols: Vec<usize> =
        header.iter().enumerate().filter(|(_, h)| h.contains("_ms_sss_")).map(|(i, _)| i).collect();
    let mut methods: Vec<String> = vec![];
    for r in &rows {
        if !methods.contains(&r[method_col]) {
            methods.push(r[method_col].clone());
        }
    }
    if !methods.iter().any(|m| m == REFERENCE) {
        bail!(
            "{}: no method {REFERENCE}; expected the SSS scenarios' reference pass",
            run.display()
        );
    }
    let frames: u32 = rows
        .iter()
        .map(|r| r[frame_col].parse::<u32>().map(|f| f + 1))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .max()
        .unwrap_or(0);
    let masks: Vec<Vec<bool>> = (0..frames)
        .map(|f| mask(&folder.method_image(REFERENCE, "sample_count", f, "png")))
        .collect::<Result<_>>()?;
    let references: Vec<Vec<f32>> = (0..frames)
        .map(|f| luminance_image(&folder.frame(REFERENCE, f, "exr")))
        .collect::<Result<_>>()?;
    let peak = references
        .iter()
        .zip(&masks)
        .flat_map(|(r, m)| r.iter().zip(m).filter(|(_, m)| **m).map(|(l, _)| *l as f64))
        .fold(0.0, f64::max);
    let mut out = vec![];
    let mut per_frame: Vec<Vec<f64>> = vec![];
    for m in &methods {
        let mine: Vec<&Vec<String>> = rows.iter().filter(|r| &r[method_col] == m).collect();
        let number = |s: &str| {
            if s.is_empty() {
                Ok(0.0)
            } else {
                s.parse::<f64>().with_context(|| {
                    format!("{}: '{s}' is not a number", folder.frames_csv().display())
                })
            }
        };
        let spp =
            mine.iter().map(|r| number(&r[spp_col])).sum::<Result<f64>>()? / mine.len() as f64;
        let ms = mine
            .iter()
            .map(|r| pass_cols.iter().map(|&c| number(&r[c])).sum::<Result<f64>>())
            .sum::<Result<f64>>()?
            / mine.len() as f64;
        let images: Vec<Vec<f32>> = (0..frames)
            .map(|f| luminance_image(&folder.frame(m, f, "exr")))
            .collect::<Result<_>>()?;
        let psnr: Vec<f64> = (0..frames as usize)
            .map(|f| psnr_luminance(&images[f], &references[f], &masks[f], peak))
            .collect();
        let smape: Vec<f64> = (1..frames as usize)
            .map(|f| smape_luminance(&images[f], &images[f - 1], &masks[f]))
            .collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        out.push(Row {
            method: m.clone(),
            spp,
            ms,
            psnr: if m == REFERENCE { f64::INFINITY } else { mean(&psnr) },
            smape: mean(&smape),
        });
        per_frame.push(smape);
    }
    let mut csv = format!("frame,{}\n", methods.join(","));
    for f in 1..frames as usize {
        let cells: Vec<String> = per_frame.iter().map(|s| format!("{:.6}", s[f - 1])).collect();
        csv.push_str(&format!("{f},{}\n", cells.join(",")));
    }
    Ok((out, csv))
}

/// The seed runs under a multi-seed folder (`seed*` with frames.csv), sorted; empty for a run.
fn seed_runs(dir: &Path) -> Result<Vec<PathBuf>> {
    if dir.join("frames.csv").exists() {
        return Ok(vec![]);
    }
    let mut runs: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.join("frames.csv").exists()
                && p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("seed"))
        })
        .collect();
    runs.sort();
    if runs.is_empty() {
        bail!("{}: no frames.csv and no seed*/frames.csv; expected a run folder", dir.display());
    }
    Ok(runs)
}

/// The one-sided 95% Student-t bounds (lower, upper) of the mean of per-seed values.
fn bounds(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, mean);
    }
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let t = StudentsT::new(0.0, 1.0, n - 1.0).expect("n > 1").inverse_cdf(0.95);
    (mean - t * sd / n.sqrt(), mean + t * sd / n.sqrt())
}

fn list(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.2}")).collect::<Vec<_>>().join(" / ")
}

/// One scenario over seeds: per method each seed's spp and PSNR and their means, then the
/// issue's relations of Table 7.3 for that test, each with its bound and verdict.
fn seeds_table(name: &str, runs: &[PathBuf]) -> Result<()> {
    let tables: Vec<Vec<Row>> =
        runs.iter().map(|r| table(r).map(|(rows, _)| rows)).collect::<Result<_>>()?;
    let per = |method: &str, f: fn(&Row) -> f64| -> Result<Vec<f64>> {
        tables
            .iter()
            .zip(runs)
            .map(|(rows, run)| {
                rows.iter()
                    .find(|r| r.method == method)
                    .map(f)
                    .with_context(|| format!("{}: no method {method}", run.display()))
            })
            .collect()
    };
    println!(
        "\n{name}, seeds {}:\n",
        runs.iter()
            .map(|r| r.file_name().unwrap_or_default().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "| method | mean spp per seed | mean | PSNR dB per seed | mean | SMAPE mean | SSS ms/frame mean |\n|---|---|---|---|---|---|---|"
    );
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    for r in &tables[0] {
        let (spp, psnr) = (per(&r.method, |r| r.spp)?, per(&r.method, |r| r.psnr)?);
        let (smape, ms) = (per(&r.method, |r| r.smape)?, per(&r.method, |r| r.ms)?);
        println!(
            "| {} | {} | {:.2} | {} | {:.2} | {:.4} | {:.2} |",
            r.method,
            list(&spp),
            mean(&spp),
            list(&psnr),
            mean(&psnr),
            mean(&smape),
            mean(&ms)
        );
    }
    let (as_, ocv, ccv) = (per("as", |r| r.spp)?, per("ocv", |r| r.spp)?, per("ccv", |r| r.spp)?);
    let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<f64>>();
    let verdict = |ok: bool| if ok { "holds" } else { "FAILS" };
    let mut relations: Vec<String> = vec![];
    let mut strictly_below = |what: &str, a: &[f64], b: &[f64]| {
        let (lo, _) = bounds(&diff(b, a));
        relations.push(format!(
            "{what}: per-seed {} − {} = {}, lower 95% bound {lo:.3} > 0: {}",
            list(b),
            list(a),
            list(&diff(b, a)),
            verdict(lo > 0.0)
        ));
    };
    strictly_below("CCV < OCV (spp)", &ccv, &ocv);
    strictly_below("OCV < AS (spp)", &ocv, &as_);
    if name.contains("flash") {
        let (pa, po, pc) =
            (per("as", |r| r.psnr)?, per("ocv", |r| r.psnr)?, per("ccv", |r| r.psnr)?);
        for (label, cv, p) in [("OCV", &ocv, &po), ("CCV", &ccv, &pc)] {
            let ratio: Vec<f64> = cv.iter().zip(&as_).map(|(c, a)| c / a).collect();
            let (_, hi) = bounds(&ratio);
            relations.push(format!(
                "{label} spp / AS spp <= 0.6: per-seed {}, upper 95% bound {hi:.3}: {}",
                list(&ratio),
                verdict(hi <= 0.6)
            ));
            let cost = diff(&pa, p);
            let (_, hi) = bounds(&cost);
            relations.push(format!(
                "PSNR(AS) − PSNR({label}) <= 2 dB: per-seed {}, upper 95% bound {hi:.2}: {}",
                list(&cost),
                verdict(hi <= 2.0)
            ));
        }
    } else {
        let (_, hi) = bounds(&as_);
        relations.push(format!(
            "AS spp <= 0.6 x 64 = 38.4: per-seed {}, upper 95% bound {hi:.2}: {}",
            list(&as_),
            verdict(hi <= 38.4)
        ));
    }
    println!();
    for r in relations {
        println!("- {name}: {r}");
    }
    Ok(())
}

fn main() -> Result<()> {
    let runs: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if runs.is_empty() {
        bail!("usage: sss_scenario_table RUN...; expected run folders of the SSS scenarios");
    }
    let (multi, single): (Vec<_>, Vec<_>) = runs
        .iter()
        .map(|r| seed_runs(r).map(|s| (r.clone(), s)))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .partition(|(_, s)| !s.is_empty());
    if !single.is_empty() {
        println!(
            "| scenario | method | mean spp | SSS ms/frame | PSNR dB vs {REFERENCE} | SMAPE |\n|---|---|---|---|---|---|"
        );
    }
    for (run, _) in &single {
        let (rows, csv) = table(run)?;
        let name = run.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        for r in rows {
            println!(
                "| {name} | {} | {:.2} | {:.2} | {:.2} | {:.4} |",
                r.method, r.spp, r.ms, r.psnr, r.smape
            );
        }
        systems::output::write_text(&run.join("sss_smape.csv"), &csv)?;
    }
    for (dir, seeds) in &multi {
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        seeds_table(&name, seeds)?;
    }
    Ok(())
}
