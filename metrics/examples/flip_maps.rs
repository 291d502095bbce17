//! `cargo run --release -p metrics --example flip_maps -- [REFERENCE.exr TEST.exr]...`: HDR-FLIP's
//! per-pixel error map by `metrics::flip_hdr` (the `flip-rs` crate) compared pixel by pixel with
//! NVIDIA's `flip-evaluator` (its Python API's map, no colour map). Without arguments: the
//! synthetic HDR pair at 1280x720 (seed 7) and the still ColorVideoVDP fixture's frame 0 (path
//! tracing, 2 spp against 64 spp, 32x18). The pairs reach NVIDIA's API as arrays: its EXR loader
//! crashes (segmentation fault, flip-evaluator 1.7) on flicker's EXRs. Prints one table row per
//! pair and implementation: max, mean and 99.9th percentile of |Δ| and the share of pixels off
//! by more than 1e-3 and 1e-2. (The hand-written FLIP this was first run against is at commit
//! 1427ae4, docs/lab/metrics-jod-flip.md.)

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, ensure};
use metrics::synthetic::synthetic_hdr_pair;
use metrics::{DEFAULT_PPD, Image, flip_hdr, load_image};

/// NVIDIA's HDR-FLIP map of the pair: both images handed to its Python API as raw f32 arrays
/// (HxWx3), the error map written back as raw f32.
fn nvidia_map(reference: &Image, test: &Image, scratch: &Path) -> anyhow::Result<Vec<f32>> {
    let raw = |img: &Image, name: &str| -> anyhow::Result<PathBuf> {
        let path = scratch.join(name);
        let bytes: Vec<u8> = img.rgb.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(&path, bytes)?;
        Ok(path)
    };
    let (rp, tp) = (raw(reference, "r.f32")?, raw(test, "t.f32")?);
    let out = scratch.join("nvidia_map.f32");
    let shape = format!("({}, {}, 3)", reference.height, reference.width);
    let script = format!(
        "import flip_evaluator as f, numpy as np\n\
         r = np.fromfile({:?}, dtype='<f4').reshape{shape}\n\
         t = np.fromfile({:?}, dtype='<f4').reshape{shape}\n\
         m, mean, _ = f.evaluate(r, t, 'HDR', applyMagma=False, parameters={{'ppd': {}}})\n\
         np.asarray(m, dtype=np.float32).reshape(-1).tofile({:?})\n",
        rp.display().to_string(),
        tp.display().to_string(),
        DEFAULT_PPD,
        out.display().to_string()
    );
    let python = metrics::python::interpreter();
    let run = Command::new(&python)
        .args(["-c", &script])
        .output()
        .context(python.display().to_string())?;
    ensure!(
        run.status.success(),
        "flip_evaluator ({}): {}",
        run.status,
        String::from_utf8_lossy(&run.stderr)
    );
    let bytes = std::fs::read(&out)?;
    Ok(bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
}

/// `| max | mean | p99.9 | > 1e-3 | > 1e-2 |` of |a - b|.
fn differences(a: &[f32], b: &[f32]) -> String {
    assert_eq!(a.len(), b.len());
    let mut d: Vec<f64> = a.iter().zip(b).map(|(x, y)| f64::from((x - y).abs())).collect();
    d.sort_by(f64::total_cmp);
    let n = d.len() as f64;
    let share = |t: f64| d.iter().filter(|&&v| v > t).count() as f64 / n * 100.0;
    format!(
        "{:.2e} | {:.2e} | {:.2e} | {:.3}% | {:.3}%",
        d[d.len() - 1],
        d.iter().sum::<f64>() / n,
        d[((n * 0.999) as usize).min(d.len() - 1)],
        share(1e-3),
        share(1e-2)
    )
}

fn main() -> anyhow::Result<()> {
    let scratch = std::env::temp_dir().join(format!("flip-maps-{}", std::process::id()));
    std::fs::create_dir_all(&scratch)?;
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let mut pairs: Vec<(String, Image, Image)> = Vec::new();
    if args.is_empty() {
        let (r, t) = synthetic_hdr_pair(1280, 720, 7);
        pairs.push(("synthetic 1280x720 (seed 7)".into(), r, t));
        let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cvvdp/static");
        pairs.push((
            "still Cornell box 32x18, frame 0".into(),
            load_image(fixture.join("reference/0000.exr"))?,
            load_image(fixture.join("test/0000.exr"))?,
        ));
    } else {
        for p in args.chunks(2) {
            ensure!(p.len() == 2, "expected pairs: REFERENCE.exr TEST.exr");
            pairs.push((p[1].display().to_string(), load_image(&p[0])?, load_image(&p[1])?));
        }
    }
    println!(
        "| pair | implementation | mean FLIP | max Δ | mean Δ | p99.9 Δ | Δ > 1e-3 | Δ > 1e-2 |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    let mean = |m: &[f32]| m.iter().map(|&v| f64::from(v)).sum::<f64>() / m.len() as f64;
    for (name, reference, test) in &pairs {
        let nvidia = nvidia_map(reference, test, &scratch)?;
        ensure!(nvidia.len() == reference.rgb.len(), "NVIDIA's map has {} pixels", nvidia.len());
        println!("| {name} | NVIDIA flip-evaluator | {:.6} | | | | | |", mean(&nvidia));
        let ours = flip_hdr(reference, test, DEFAULT_PPD).map;
        println!(
            "| {name} | metrics::flip_hdr (flip-rs 0.1.2) | {:.6} | {} |",
            mean(&ours),
            differences(&ours, &nvidia)
        );
    }
    std::fs::remove_dir_all(&scratch).ok();
    Ok(())
}
