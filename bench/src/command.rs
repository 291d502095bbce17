//! `flicker bench`'s two forms as the command line runs them: the tables printed (and written
//! with `--out`) and the JSON (`--json`).

use std::path::PathBuf;

/// `flicker bench --nirc`: the cache's throughput (crate::nirc_throughput) as a table, then
/// whole frames (crate::nirc_frames); `json` gets both.
pub fn nirc(
    out: Option<PathBuf>,
    json: Option<PathBuf>,
    batch: u32,
    queries: u32,
    repeats: u32,
    frames: u32,
    resolution: (u32, u32),
) -> anyhow::Result<()> {
    let gpu = render::gpu::Gpu::new()?;
    eprintln!(
        "bench: NIRC at width 64, {batch} training records, {queries} queries, {repeats} repetitions"
    );
    let r = crate::nirc_throughput::run(
        &gpu,
        &nirc::NircCacheSettings::default(),
        None,
        batch,
        queries,
        repeats,
    )?;
    let md = format!(
        "Adapter: {}; MLP form: {:?} (width {}, {} hidden layers)\n\n| measure | value |\n|---|---:|\n\
         | FMA ceiling (GFLOP/s) | {:.1} |\n| training (records/s) | {:.0} |\n| training (GFLOP/s, % of ceiling) | {:.2} ({:.1}%) |\n\
         | EMA-only inference (queries/s) | {:.0} |\n| inference (GFLOP/s, % of ceiling) | {:.2} ({:.1}%) |\n| blend (queries/s) | {:.0} |\n\
         | blend overhead (% of a training step + EMA-only inference) | {:.1} |\n| blend overhead (% of EMA-only inference) | {:.1} |\n\
         | one 64x64 layer, 4x16 blocks (GFLOP/s) | {:.2} |\n| one 64x64 layer, 16x16 blocks (GFLOP/s) | {:.2} |\n",
        r.adapter,
        r.placement,
        r.width,
        r.hidden_layers,
        r.peak_gflops,
        r.train_records_per_s,
        r.train_gflops,
        r.train_percent_of_peak,
        r.ema_only_queries_per_s,
        r.infer_gflops,
        r.infer_percent_of_peak,
        r.blend_queries_per_s,
        r.blend_overhead_step_percent,
        r.blend_overhead_infer_percent,
        r.layer_probe_4x16_gflops,
        r.layer_probe_16x16_gflops
    );
    let mut md = md;
    md.push_str(&format!(
        "| training with sparse grid updates (records/s) | {:.0} |\n| training with sparse grid updates (GFLOP/s, % of ceiling) | {:.2} ({:.1}%) |\n| grid quads the sparse step touched | {} of {} |\n",
        r.train_sparse_records_per_s,
        r.train_sparse_gflops,
        r.train_sparse_percent_of_peak,
        r.sparse_touched_quads,
        r.grid_quads
    ));
    for (title, stages) in
        [("dense", &r.train_stages_ms), ("sparse grid updates", &r.train_sparse_stages_ms)]
    {
        md.push_str(&format!(
            "\n| training step ({title}), stage by stage (each submitted alone) | ms |\n|---|---:|\n"
        ));
        for (name, ms) in stages {
            md.push_str(&format!("| {name} | {ms:.2} |\n"));
        }
    }
    use anyhow::Context as _;
    drop(gpu);
    // The throughput is printed first, and written even if the frames fail.
    print!("{md}");
    let frames = if frames > 0 {
        let scratch =
            std::env::temp_dir().join(format!("flicker-bench-nirc-frames-{}", std::process::id()));
        crate::nirc_frames::run(resolution, 2, frames, &scratch).map(Some)
    } else {
        Ok(None)
    };
    let table = frames.as_ref().ok().and_then(|t| t.clone());
    if let Some(t) = &table {
        let section = format!("\n{}", crate::nirc_frames::markdown(t));
        print!("{section}");
        md.push_str(&section);
    }
    let targets = crate::nirc_targets::targets(&r, table.as_ref());
    let section = crate::nirc_targets::markdown(&targets);
    print!("{section}");
    md.push_str(&section);
    if let Some(path) = out {
        frame::output::write_text(&path, &md)?;
    }
    if let Some(path) = json {
        let j = BenchJson {
            throughput: r,
            blend_overhead_frame_percent: table.as_ref().map(|t| t.blend_overhead_frame_percent),
            frames: table,
            targets,
        };
        frame::output::write_text(&path, &serde_json::to_string_pretty(&j)?)?;
    }
    frames
        .map(|_| ())
        .context("the whole-frame part of the NIRC bench (the throughput above was kept)")
}

/// `flicker bench`: the speed tables (crate::speed) and, unless `no_metrics`, the image metrics'
/// timings (crate::image_metrics).
/// `flicker bench --memory`: the device memory table of every method (`memory_table`).
pub fn memory(out: Option<PathBuf>, json: Option<PathBuf>) -> anyhow::Result<()> {
    let resolutions = crate::speed::BenchOptions::default().resolutions;
    let scratch = std::env::temp_dir().join(format!("flicker-bench-memory-{}", std::process::id()));
    let (md, rows) = crate::memory_table::table(&resolutions, &scratch)?;
    print_and_write(&md, out, json, &rows)
}

/// Prints the Markdown; writes it to `out` and `value` as JSON to `json` where given.
fn print_and_write(
    md: &str,
    out: Option<PathBuf>,
    json: Option<PathBuf>,
    value: &impl serde::Serialize,
) -> anyhow::Result<()> {
    print!("{md}");
    if let Some(path) = out {
        frame::output::write_text(&path, md)?;
    }
    if let Some(path) = json {
        frame::output::write_text(&path, &serde_json::to_string_pretty(value)?)?;
    }
    Ok(())
}

/// The image metrics' timings (crate::image_metrics) at 1280x720, with JOD's rows at 160x90
/// too: the Markdown section and the report.
fn metrics_section(repeats: u32) -> anyhow::Result<(String, crate::image_metrics::BenchReport)> {
    let mut md = String::new();
    eprintln!("bench: image metrics at 1280x720");
    let args = crate::image_metrics::BenchArgs {
        width: 1280,
        height: 720,
        repeats,
        no_reference: false,
        smape_only: false,
    };
    let r = crate::image_metrics::bench(&args)?;
    md.push_str(&format!(
        "\n## Image metrics, {}x{} HDR pair ({} threads)\n\n| metric | ms |\n|---|---:|\n| SMAPE | {:.2} |\n| HDR-FLIP (flicker) | {:.1} |\n",
        r.width, r.height, r.threads, r.smape_ms, r.flip_hdr_ms.unwrap_or(f64::NAN)
    ));
    if let (Some(ms), Some(speedup)) = (r.reference_flip_ms, r.speedup) {
        md.push_str(&format!("| HDR-FLIP (flip-evaluator) | {ms:.1} |\n\nflip-evaluator time / flicker time: {speedup:.2}\n"));
    }
    md.push_str(&format!("\nPer frame: HDR-FLIP of one pair; ColorVideoVDP (JOD) per frame of a {}-frame video (the synthetic pair, fresh noise per frame; flicker on {} threads, `cvvdp` on the CPU with one torch thread, random frames):\n\n| size | HDR-FLIP ms | JOD ms (flicker) | JOD ms (cvvdp) | JOD |\n|---|---:|---:|---:|---:|\n", crate::image_metrics::JOD_FRAMES, r.threads));
    for t in &r.jod {
        let cvvdp = match &t.cvvdp {
            Ok(ms) => format!("{ms:.1}"),
            Err(why) => why.clone(),
        };
        md.push_str(&format!(
            "| {}x{} | {:.1} | {:.1} | {cvvdp} | {:.3} |\n",
            t.width, t.height, t.flip_ms, t.ms_per_frame, t.jod
        ));
    }
    Ok((md, r))
}

/// What measured the image metrics: this machine's CPU threads.
fn cpu_adapter(threads: usize) -> String {
    format!("cpu ({threads} threads)")
}

/// `flicker bench --metrics-only`: the image metrics' timings alone (no GPU). Returns what
/// measured and the results history's entries (the ratio to NVIDIA's flip-evaluator).
pub fn metrics(
    out: Option<PathBuf>,
    json: Option<PathBuf>,
    repeats: u32,
) -> anyhow::Result<(String, Vec<History>)> {
    let (md, r) = metrics_section(repeats)?;
    print_and_write(&md, out, json, &r)?;
    let entries = tools::history::sources::bench_metrics_entries(&serde_json::to_value(&r)?);
    Ok((cpu_adapter(r.threads), entries))
}

/// A results-history entry of the bench.
pub type History = tools::history::Entry;

/// The results-history record of a bench run (`form`: `speed` or `metrics`).
pub fn record(form: &str, adapter: &str, entries: Vec<History>) -> tools::history::Record {
    let mut r = tools::history::Record::now(
        tools::history::Kind::Bench,
        form,
        "-",
        adapter,
        std::path::Path::new("."),
    );
    r.entries = entries;
    r
}

pub fn speed(
    out: Option<PathBuf>,
    json: Option<PathBuf>,
    rays: u32,
    frames: u32,
    no_metrics: bool,
    repeats: u32,
) -> anyhow::Result<(String, Vec<History>)> {
    let opts = crate::speed::BenchOptions { rays, frames, ..Default::default() };
    let report = crate::speed::run(&opts, |step| eprintln!("bench: {step}"))?;
    let mut md = report.markdown;
    let mut entries = tools::history::sources::bench_speed_entries(&report.json);
    if !no_metrics {
        let (section, r) = metrics_section(repeats)?;
        md.push_str(&section);
        entries.extend(tools::history::sources::bench_metrics_entries(&serde_json::to_value(&r)?));
    }
    print!("{md}");
    if let Some(path) = out {
        frame::output::write_text(&path, &md)?;
    }
    if let Some(path) = json {
        frame::output::write_text(&path, &serde_json::to_string_pretty(&report.json)?)?;
    }
    let a = &report.json["adapter"];
    let adapter =
        format!("{} / {}", a["name"].as_str().unwrap_or("?"), a["backend"].as_str().unwrap_or("?"));
    Ok((adapter, entries))
}

/// The JSON of `flicker bench --nirc`: the throughput report and, unless skipped, whole frames.
#[derive(serde::Serialize)]
struct BenchJson {
    #[serde(flatten)]
    pub throughput: crate::nirc_throughput::BenchReport,
    /// The blend's cost over EMA-only in whole frames (`frames`), as the paper's Table 1.
    pub blend_overhead_frame_percent: Option<f64>,
    pub frames: Option<crate::nirc_frames::Table1>,
    /// The speed targets as shares of the ceiling, beside the measured shares.
    pub targets: Vec<crate::nirc_targets::Target>,
}
