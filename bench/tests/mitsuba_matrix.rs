//! The WGSL path tracer against Mitsuba 3, pixel by pixel, over a matrix of small scenes: every
//! light type (point, spot, directional, area, emissive meshes, the constant environment), a
//! sRGB texture, metal from a mirror to roughness 1, a dielectric over a coloured base from
//! roughness 0.2 to 1, the depth limits 1 (direct light), 2 and unlimited, a homogeneous and a
//! heterogeneous (grid) medium, and a curved mesh with smooth shading normals.
//! bench::mitsuba exports each scene from the same `SceneDesc`; scripts/mitsuba_matrix.py
//! renders them all in one Python process with Mitsuba's scalar CPU path tracer, K independent
//! images of each (seeds), while this test renders K independent images of each on the GPU:
//! each pixel's mean and its standard error from the spread of the K images, on both sides. Per scene, three tests whose tolerances are the two estimates' standard errors:
//! Welch's t per pixel (the smallest p-value, Bonferroni over the pixels), the count of pixels
//! with p < 1% against its binomial law, and the z of the image means. The family of
//! 3 x scenes tests is held at a 1% false-alarm rate by Bonferroni.
//!
//! Not in the matrix, because Mitsuba cannot express them: screen-space subsurface scattering
//! (Burley's diffusion profile; the SSS method's tests use closed forms), the methods' caches
//! (not renderers of the reference), spot lights with a soft edge (our smoothstep in the cosine
//! is not Mitsuba's linear falloff in the angle), directional lights with an angular radius
//! (Mitsuba's is a delta), shading normals on paths that leave a surface on the side where its
//! shading and geometric normals disagree (ours ends such a path, Mitsuba's BSDFs see the
//! shading frame only), so the smooth-normal scene is lit directly from the camera's side.
//! The scenes with media are rendered, as their references are, by our volumetric path tracer
//! (frame::scene_medium), against Mitsuba's `volpath`; the grid medium goes to Mitsuba as our
//! baked grid itself (a `gridvolume`, nearest-neighbour as ours).
//! `FLICKER_MITSUBA_CASES=a,b` runs only the named scenes (for breaking the renderer on
//! purpose); the significance stays that of the whole matrix. `FLICKER_MITSUBA_DUMP=1` prints
//! both images (the tested channel per pixel).

#[path = "mitsuba_matrix/scenes.rs"]
mod scenes;
#[path = "mitsuba_matrix/stats.rs"]
mod stats;

use bench::mitsuba::{Integrator, python, write_scene_with_media};
use frame::scene_medium::{REFERENCE_SETTINGS, SceneMedium, render_volume};
use render::frame_bindings::FrameBindings;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_gpu::SceneGpu;
use scenes::SIZE;
use stats::{Estimate, compare};

/// Our independent images per scene (their spread gives each pixel's standard error).
const IMAGES: u32 = 16;
/// The false-alarm rate of the whole matrix.
const FAMILY_ALPHA: f64 = 0.01;
/// Russian roulette from this depth on in both renderers (Mitsuba's default).
const RR_DEPTH: u32 = 5;

#[test]
fn path_tracer_matches_mitsuba_over_the_matrix() {
    let all = scenes::matrix();
    let tests = 3 * all.len();
    let only = std::env::var("FLICKER_MITSUBA_CASES").ok();
    let cases: Vec<scenes::Case> = all
        .into_iter()
        .filter(|c| only.as_ref().is_none_or(|o| o.split(',').any(|n| n == c.name)))
        .collect();
    assert!(!cases.is_empty(), "no scene named in FLICKER_MITSUBA_CASES={only:?}");

    // Mitsuba: every scene exported, then rendered in one background process.
    let python = python().expect("a Python with the mitsuba package (scripts/setup-tests.sh installs it into .venv; FLICKER_PYTHON names another)");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let mut jobs = Vec::new();
    for case in &cases {
        let integrator = Integrator { max_depth: Some(case.max_depth + 1), rr_depth: RR_DEPTH };
        let xml = write_scene_with_media(
            &case.scene,
            &case.media,
            (SIZE, SIZE),
            &integrator,
            &dir.join(case.name),
        )
        .unwrap_or_else(|e| panic!("{}: {e:#}", case.name));
        jobs.push(serde_json::json!({
            "xml": xml, "spp": case.spp / IMAGES, "images": IMAGES, "seed": 5,
            "out": dir.join(case.name).join("images.f32"),
        }));
    }
    let jobs_file = dir.join("jobs.json");
    std::fs::write(&jobs_file, serde_json::to_string(&jobs).unwrap()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/mitsuba_matrix.py");
    let mitsuba = std::process::Command::new(&python)
        .arg(script)
        .arg(&jobs_file)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting Mitsuba");

    // Ours, meanwhile: IMAGES independent images per scene.
    let gpu = testkit::test_scenes::gpu();
    let mut ours = Vec::new();
    for case in &cases {
        let settings = PathTracerSettings {
            width: SIZE,
            height: SIZE,
            max_depth: case.max_depth,
            rr_start_depth: RR_DEPTH,
        };
        let mut sg = SceneGpu::new(gpu, &case.scene, settings).unwrap();
        sg.update(gpu, &case.scene);
        let (spp, seed) = (case.spp / IMAGES, |k: u32| 1000 + k as u64);
        let images: Vec<Vec<[f32; 4]>> = if case.media.is_empty() {
            let mut tracer = PathTracer::new(gpu, &sg).unwrap();
            (0..IMAGES)
                .map(|k| tracer.render_reference(gpu, &sg, spp, seed(k), 0, &mut |_, _| {}))
                .collect::<Result<_, _>>()
                .unwrap()
        } else {
            // As frame::reference renders a scene with media.
            let bindings = FrameBindings::new(gpu, &sg);
            let mut medium = SceneMedium::new(gpu, &case.media);
            (0..IMAGES)
                .map(|k| {
                    render_volume(
                        gpu,
                        &sg,
                        &bindings,
                        &mut medium,
                        &REFERENCE_SETTINGS,
                        spp,
                        seed(k),
                        0,
                    )
                    .map(|(px, _, _)| px)
                })
                .collect::<Result<_, _>>()
                .unwrap()
        };
        ours.push(images);
    }

    let out = mitsuba.wait_with_output().expect("Mitsuba's output");
    assert!(out.status.success(), "Mitsuba failed:\n{}", String::from_utf8_lossy(&out.stderr));
    eprintln!("{}", String::from_utf8_lossy(&out.stdout));

    // Per scene, per pixel one channel (R, G, B cycling over the pixels, so that the pixels
    // stay independent trials and every channel is tested).
    let alpha = FAMILY_ALPHA / tests as f64;
    let pixels = (SIZE * SIZE) as usize;
    let mut failures = Vec::new();
    eprintln!(
        "{:<18} {:>5} {:>9} {:>8} {:>9} {:>9} {:>8} {:>9} level {alpha:.1e}",
        "scene", "spp", "p_pixel", "worst_t", "outliers", "p_count", "mean_z", "mean_rel"
    );
    for (case, images) in cases.iter().zip(&ours) {
        let raw = std::fs::read(dir.join(case.name).join("images.f32")).unwrap();
        let theirs: Vec<f32> =
            raw.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        assert_eq!(theirs.len(), IMAGES as usize * pixels * 3, "{}: Mitsuba's images", case.name);
        // Each pixel's mean over the K images and its squared standard error.
        let estimate = |xs: &mut dyn Iterator<Item = f64>| {
            let xs: Vec<f64> = xs.collect();
            let k = xs.len() as f64;
            let mean = xs.iter().sum::<f64>() / k;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
            Estimate { mean, se2: var / k, dof: k - 1.0 }
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for i in 0..pixels {
            let c = i % 3;
            a.push(estimate(&mut images.iter().map(|img| img[i][c] as f64)));
            b.push(estimate(
                &mut (0..IMAGES as usize).map(|k| theirs[(k * pixels + i) * 3 + c] as f64),
            ));
        }
        let their_sum: f64 = b.iter().map(|e| e.mean).sum();
        assert!(their_sum / pixels as f64 > 1e-3, "{}: Mitsuba's image is black", case.name);
        if std::env::var("FLICKER_MITSUBA_DUMP").is_ok() {
            for y in 0..SIZE as usize {
                let row = |v: &[Estimate]| {
                    (0..SIZE as usize)
                        .map(|x| format!("{:5.2}", v[y * SIZE as usize + x].mean))
                        .collect::<Vec<_>>()
                        .join(" ")
                };
                eprintln!("{}  |  {}", row(&a), row(&b));
            }
        }
        // Both renderers sum a pixel's samples in f32: a mean is exact to spp ulps at most.
        let v = compare(&a, &b, case.spp as f64 * f32::EPSILON as f64 / 2.0);
        eprintln!(
            "{:<18} {:>5} {:>9.2e} {:>8.2} {:>4}/{:<4.1} {:>9.2e} {:>8.2} {:>+9.4}",
            case.name,
            case.spp,
            v.p_max,
            v.worst_t,
            v.outliers,
            v.expected_outliers,
            v.p_count,
            v.mean_z,
            v.mean_rel
        );
        let (x, y) = (v.worst_pixel as u32 % SIZE, v.worst_pixel as u32 / SIZE);
        if v.p_max < alpha {
            failures.push(format!(
                "{}: pixel ({x}, {y}) differs by t = {:.2} (p = {:.2e} after Bonferroni over {} pixels)",
                case.name, v.worst_t, v.p_max, v.pixels
            ));
        }
        if v.p_count < alpha {
            failures.push(format!(
                "{}: {} pixels with p < {} where {:.1} are expected (p = {:.2e})",
                case.name,
                v.outliers,
                stats::OUTLIER_LEVEL,
                v.expected_outliers,
                v.p_count
            ));
        }
        if v.p_mean < alpha {
            failures.push(format!(
                "{}: image means differ by {:+.4} relative, z = {:.2} (p = {:.2e})",
                case.name, v.mean_rel, v.mean_z, v.p_mean
            ));
        }
    }
    assert!(failures.is_empty(), "disagreements at level {alpha:.1e}:\n{}", failures.join("\n"));
}
