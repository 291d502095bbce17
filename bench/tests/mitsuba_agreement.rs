//! Our path tracer against an independent one: the Lambertian Cornell box rendered by the WGSL
//! path tracer and by Mitsuba 3's scalar CPU path tracer (bench::mitsuba exports the scene;
//! scripts/setup-tests.sh installs Mitsuba). Both converge to the same image, so they agree pixel by
//! pixel and in the image mean within the standard errors of the two estimates, each measured
//! from the spread of K independent images (the statistics of bench/tests/mitsuba_matrix.rs).
//! A fixed relative margin would not do: at 2048 paths per pixel the image mean of one render
//! varies by about 1% (sd) from seed to seed, so a margin of a few sigma is a fitted number.

#[path = "mitsuba_matrix/stats.rs"]
mod stats;

use bench::mitsuba::{Integrator, python, write_scene};
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_gpu::SceneGpu;
use stats::{Estimate, compare};

/// Independent images per renderer: the standard errors come from their spread.
const IMAGES: u32 = 16;
/// Family-wise false-alarm rate over the nine tests (pixel, outlier count, mean; per channel).
const FAMILY_ALPHA: f64 = 0.01;

#[test]
fn lambertian_cornell_box_matches_mitsuba() {
    let (size, spp) = (16u32, 2048u32);
    let scene = bench::mitsuba::lambertian_cornell_box((size, size)).unwrap();

    let python = python().expect("a Python with the mitsuba package (scripts/setup-tests.sh installs it into .venv; FLICKER_PYTHON names another)");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let xml = write_scene(&scene, (size, size), &Integrator { max_depth: None, rr_depth: 3 }, &dir)
        .unwrap();
    let out = dir.join("images.f32");
    let jobs = serde_json::json!([{
        "xml": xml, "spp": spp / IMAGES, "images": IMAGES, "seed": 5, "out": out,
    }]);
    let jobs_file = dir.join("jobs.json");
    std::fs::write(&jobs_file, serde_json::to_string(&jobs).unwrap()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/mitsuba_matrix.py");
    // Mitsuba renders on the CPU while ours runs.
    let mitsuba = std::process::Command::new(&python)
        .arg(script)
        .arg(&jobs_file)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting Mitsuba");

    let gpu = testkit::test_scenes::gpu();
    let mut sg = SceneGpu::new(
        gpu,
        &scene,
        PathTracerSettings { width: size, height: size, max_depth: 1000, rr_start_depth: 3 },
    )
    .unwrap();
    let mut tracer = PathTracer::new(gpu, &sg).unwrap();
    sg.update(gpu, &scene);
    let ours: Vec<Vec<[f32; 4]>> = (0..IMAGES)
        .map(|k| {
            tracer.render_reference(gpu, &sg, spp / IMAGES, 1000 + k as u64, 0, &mut |_, _| {})
        })
        .collect::<Result<_, _>>()
        .unwrap();

    let run = mitsuba.wait_with_output().expect("Mitsuba's output");
    assert!(run.status.success(), "Mitsuba failed:\n{}", String::from_utf8_lossy(&run.stderr));
    let raw = std::fs::read(&out).unwrap();
    let theirs: Vec<f32> =
        raw.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    let pixels = (size * size) as usize;
    assert_eq!(theirs.len(), IMAGES as usize * pixels * 3, "Mitsuba's images");

    let estimate = |xs: &mut dyn Iterator<Item = f64>| {
        let xs: Vec<f64> = xs.collect();
        let k = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / k;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
        Estimate { mean, se2: var / k, dof: k - 1.0 }
    };
    let alpha = FAMILY_ALPHA / 9.0;
    let mut failures = Vec::new();
    for c in 0..3 {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for i in 0..pixels {
            a.push(estimate(&mut ours.iter().map(|img| img[i][c] as f64)));
            b.push(estimate(
                &mut (0..IMAGES as usize).map(|k| theirs[(k * pixels + i) * 3 + c] as f64),
            ));
        }
        let their_mean = b.iter().map(|e| e.mean).sum::<f64>() / pixels as f64;
        assert!(
            their_mean > 0.01,
            "Mitsuba's image is black in channel {c}: the export lost the light"
        );
        // Both renderers sum a pixel's samples in f32: a mean is exact to spp ulps at most.
        let v = compare(&a, &b, spp as f64 * f32::EPSILON as f64 / 2.0);
        eprintln!(
            "channel {c}: Mitsuba's mean {their_mean:.5}, ours {:+.4} relative (z = {:.2}, p = {:.2e}); \
             worst pixel t = {:.2} (p = {:.2e} after Bonferroni); {} outliers where {:.1} expected (p = {:.2e})",
            v.mean_rel,
            v.mean_z,
            v.p_mean,
            v.worst_t,
            v.p_max,
            v.outliers,
            v.expected_outliers,
            v.p_count
        );
        let (x, y) = (v.worst_pixel as u32 % size, v.worst_pixel as u32 / size);
        if v.p_max < alpha {
            failures.push(format!(
                "channel {c}: pixel ({x}, {y}) differs by t = {:.2} (p = {:.2e} after Bonferroni over {} pixels)",
                v.worst_t, v.p_max, v.pixels
            ));
        }
        if v.p_count < alpha {
            failures.push(format!(
                "channel {c}: {} pixels with p < {} where {:.1} are expected (p = {:.2e})",
                v.outliers,
                stats::OUTLIER_LEVEL,
                v.expected_outliers,
                v.p_count
            ));
        }
        if v.p_mean < alpha {
            failures.push(format!(
                "channel {c}: image means differ by {:+.4} relative, z = {:.2} (p = {:.2e})",
                v.mean_rel, v.mean_z, v.p_mean
            ));
        }
    }
    assert!(failures.is_empty(), "disagreements at level {alpha:.1e}:\n{}", failures.join("\n"));
}
