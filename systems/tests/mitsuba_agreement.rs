//! Our path tracer against an independent one: the Lambertian Cornell box rendered by the WGSL
//! path tracer and by Mitsuba 3's scalar CPU path tracer (systems::mitsuba exports the scene;
//! scripts/setup.sh installs Mitsuba). Both converge to the same image, so the images' means and
//! their 4x4-pixel block means agree within the noise of the two estimates.

use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_gpu::SceneGpu;
use systems::mitsuba::{Integrator, python, render, write_scene};

#[test]
fn lambertian_cornell_box_matches_mitsuba() {
    let (size, spp) = (16u32, 2048u32);
    let scene = systems::mitsuba::lambertian_cornell_box((size, size)).unwrap();
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let mut sg = SceneGpu::new(
        &gpu,
        &scene,
        PathTracerSettings { width: size, height: size, max_depth: 1000, rr_start_depth: 3 },
    )
    .unwrap();
    let mut tracer = PathTracer::new(&gpu, &sg).unwrap();
    sg.update(&gpu, &scene);
    let ours = tracer.render_reference(&gpu, &sg, spp, 7, 0, &mut |_, _| {}).unwrap();

    let python = python().expect("python3 with the mitsuba package (scripts/setup.sh installs it)");
    let dir = std::env::temp_dir().join(format!("flicker-mitsuba-{}", std::process::id()));
    let xml = write_scene(&scene, (size, size), &Integrator { max_depth: None, rr_depth: 3 }, &dir)
        .unwrap();
    let exr = dir.join("mitsuba.exr");
    let run = render(&python, &xml, spp, &exr).unwrap();
    let (w, h, theirs) = systems::output::read_exr(&exr).unwrap();
    assert_eq!((w, h), (size, size));
    std::fs::remove_dir_all(&dir).unwrap();

    let lum = |p: &[f32; 4]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
    let mean = |img: &[[f32; 4]], c: usize| {
        img.iter().map(|p| p[c] as f64).sum::<f64>() / img.len() as f64
    };
    for c in 0..3 {
        let (a, b) = (mean(&ours, c), mean(&theirs, c));
        eprintln!(
            "channel {c}: ours {a:.5}, Mitsuba {b:.5} (Mitsuba's own mean {:.5}), ratio {:.4}",
            run.mean_rgb[c],
            a / b
        );
        assert!(b > 0.01, "Mitsuba's image is black in channel {c}: the export lost the light");
        // 524k paths each: the means' noise is a few tenths of a percent.
        assert!((a / b - 1.0).abs() < 0.015, "channel {c}: mean {a} against Mitsuba's {b}");
    }
    // Block means locate the image: a mirrored camera, a wrong field of view or a light on the
    // wrong side moves them by far more than the noise of 32k paths per block (a few percent).
    let block = 4;
    let mut worst: f64 = 0.0;
    for by in 0..size / block {
        for bx in 0..size / block {
            let (mut a, mut b) = (0.0, 0.0);
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    let i = (y * size + x) as usize;
                    a += lum(&ours[i]);
                    b += lum(&theirs[i]);
                }
            }
            let rel = (a - b).abs() / b.max(1e-6);
            worst = worst.max(rel);
            assert!(rel < 0.1, "block ({bx}, {by}): luminance {a} against Mitsuba's {b}");
        }
    }
    eprintln!("largest relative difference of a 4x4 block's luminance: {worst:.4}");
}
