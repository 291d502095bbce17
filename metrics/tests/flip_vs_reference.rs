//! FLIP agrees with NVIDIA's reference implementation (`pip install flip-evaluator`): on varied
//! LDR and HDR pairs the mean is within 0.001 and the per-pixel maps within 0.01 on 99% of
//! pixels. The reference tool runs as a subprocess on files this test writes; its grayscale map
//! is an 8-bit PNG (quantisation ±0.002, well inside the tolerance).

use std::path::Path;

use metrics::reference_flip::{reference_flip_available, reference_flip_command};
use metrics::synthetic::{hash01, synthetic_hdr_pair};
use metrics::{DEFAULT_PPD, Image, flip_hdr, flip_ldr, load_image, write_exr, write_png_srgb};

const W: u32 = 80;
const H: u32 = 60;

fn work_dir() -> tempfile::TempDir {
    tempfile::Builder::new().prefix("metrics-flip-ref-").tempdir().unwrap()
}

/// A textured LDR image: gradients, a checkerboard, a disc and fine stripes.
fn ldr_base() -> Image {
    Image::from_fn(W, H, |x, y| {
        let (u, v) = (x as f32 / W as f32, y as f32 / H as f32);
        let checker = ((x / 8 + y / 8) % 2) as f32;
        let (dx, dy) = (u - 0.3, v - 0.6);
        if dx * dx + dy * dy < 0.03 {
            return [0.9, 0.2, 0.1];
        }
        if x > 60 {
            let stripe = (x % 2) as f32;
            return [stripe, stripe * 0.8, 0.3];
        }
        [0.1 + 0.6 * u * checker + 0.2 * v, 0.2 + 0.5 * v, 0.5 * (1.0 - u) + 0.3 * checker]
    })
}

fn map_image(img: &Image, f: impl Fn(u32, u32, [f32; 3]) -> [f32; 3]) -> Image {
    Image::from_fn(img.width, img.height, |x, y| f(x, y, img.get(x, y)))
}

fn box_blur(img: &Image) -> Image {
    map_image(img, |x, y, _| {
        let mut s = [0.0; 3];
        for (dx, dy) in (-1i32..=1).flat_map(|a| (-1i32..=1).map(move |b| (a, b))) {
            let xx = (x as i32 + dx).clamp(0, img.width as i32 - 1) as u32;
            let yy = (y as i32 + dy).clamp(0, img.height as i32 - 1) as u32;
            let p = img.get(xx, yy);
            for c in 0..3 {
                s[c] += p[c] / 9.0;
            }
        }
        s
    })
}

/// Runs the reference tool; returns (mean, map).
fn reference(dir: &Path, name: &str, r: &Path, t: &Path, ppd: f32) -> (f64, Vec<f32>) {
    let out = reference_flip_command()
        .args([
            "-r".as_ref(),
            r.as_os_str(),
            "-t".as_ref(),
            t.as_os_str(),
            "-d".as_ref(),
            dir.as_os_str(),
        ])
        .args(["-b", name, "-ppd", &ppd.to_string(), "-nm", "-nexm", "-v", "2"])
        .output()
        .expect("run python3 -m flip_evaluator.flip_python_api");
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "reference FLIP failed on {name}: {stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mean_line = stdout
        .lines()
        .find(|l| l.contains("Mean:"))
        .unwrap_or_else(|| panic!("no mean in:\n{stdout}"));
    let mean: f64 = mean_line.split(':').nth(1).unwrap().trim().parse().unwrap();
    let png =
        ::image::open(dir.join(format!("{name}.png"))).expect("reference error map").to_rgb8();
    let map = png.pixels().map(|p| p[0] as f32 / 255.0).collect();
    (mean, map)
}

fn check(name: &str, ours_mean: f64, ours_map: &[f32], reference: (f64, Vec<f32>)) {
    let (ref_mean, ref_map) = reference;
    assert_eq!(ours_map.len(), ref_map.len());
    let bad = ours_map.iter().zip(&ref_map).filter(|(a, b)| (**a - **b).abs() > 0.01).count();
    let worst = ours_map.iter().zip(&ref_map).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    eprintln!(
        "{name}: mean ours {ours_mean:.6} reference {ref_mean:.6}; pixels off by > 0.01: {bad}; worst {worst:.4}"
    );
    assert!(
        (ours_mean - ref_mean).abs() < 0.001,
        "{name}: mean FLIP {ours_mean} vs reference {ref_mean}"
    );
    assert!(
        bad as f64 <= 0.01 * ref_map.len() as f64,
        "{name}: {bad} of {} pixels differ by more than 0.01",
        ref_map.len()
    );
    assert!(ref_mean > 0.005, "{name}: the pair must actually differ (reference mean {ref_mean})");
}

#[test]
fn flip_matches_nvidia_reference() {
    // A missing tool fails the test: FLIP is never reported as validated when it was not.
    assert!(
        reference_flip_available(),
        "NVIDIA's FLIP is not installed: `python3 -m flip_evaluator.flip_python_api -h` failed (run scripts/setup-tests.sh, or set FLICKER_PYTHON to a Python that has flip-evaluator)"
    );
    let tmp = work_dir();
    let dir = tmp.path().to_path_buf();
    let base = ldr_base();
    let ldr_pairs: Vec<(&str, Image, f32)> = vec![
        (
            "ldr_noise",
            map_image(&base, |x, y, p| {
                p.map(|c| (c + 0.3 * (hash01(x, y, 3) - 0.5)).clamp(0.0, 1.0))
            }),
            DEFAULT_PPD,
        ),
        ("ldr_blur", box_blur(&box_blur(&base)), DEFAULT_PPD),
        ("ldr_shift", map_image(&base, |x, y, _| base.get(x.saturating_sub(2), y)), DEFAULT_PPD),
        (
            "ldr_colour_shift",
            map_image(&base, |_, _, p| [p[0], (p[1] * 0.8).min(1.0), (p[2] * 1.3 + 0.05).min(1.0)]),
            30.0,
        ),
    ];
    let ref_png = dir.join("ldr_reference.png");
    write_png_srgb(&base, &ref_png).unwrap();
    let r = load_image(&ref_png).unwrap();
    for (name, test, ppd) in &ldr_pairs {
        let path = dir.join(format!("{name}_test.png"));
        write_png_srgb(test, &path).unwrap();
        let t = load_image(&path).unwrap();
        let ours = flip_ldr(&r, &t, *ppd);
        check(name, ours.mean, &ours.map, reference(&dir, name, &ref_png, &path, *ppd));
    }

    let (hdr_ref, hdr_noisy) = synthetic_hdr_pair(96, 64, 11);
    let hdr_pairs: Vec<(&str, Image, Image)> = vec![
        ("hdr_wide_range_noise", hdr_ref.clone(), hdr_noisy),
        (
            "hdr_shift_and_exposure",
            hdr_ref.clone(),
            map_image(&hdr_ref, |x, y, _| hdr_ref.get(x.saturating_sub(1), y).map(|c| c * 1.5)),
        ),
        (
            "hdr_colour_shift_dark",
            map_image(&hdr_ref, |_, _, p| p.map(|c| c * 0.01)),
            map_image(&hdr_ref, |_, _, p| [p[0] * 0.012, p[1] * 0.01, p[2] * 0.007]),
        ),
    ];
    for (name, reference_img, test) in &hdr_pairs {
        let (rp, tp) = (dir.join(format!("{name}_ref.exr")), dir.join(format!("{name}_test.exr")));
        write_exr(reference_img, &rp).unwrap();
        write_exr(test, &tp).unwrap();
        let ours = flip_hdr(&load_image(&rp).unwrap(), &load_image(&tp).unwrap(), DEFAULT_PPD);
        check(name, ours.mean, &ours.map, reference(&dir, name, &rp, &tp, DEFAULT_PPD));
    }
}
