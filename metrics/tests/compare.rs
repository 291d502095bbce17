//! `compare REFERENCE TEST` on files: the numbers equal the library's, the map is written, and
//! bad input is reported with the file name.

use metrics::compare::{CompareOptions, FlipMode, compare, compare_files};
use metrics::{
    DEFAULT_PPD, Image, flip_hdr, flip_ldr, load_image, psnr, smape, write_exr, write_png_srgb,
};

fn dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("metrics-compare-{name}-")).tempdir().unwrap()
}

#[test]
fn compare_matches_library_and_writes_map() {
    let tmp = dir("ok");
    let d = tmp.path().to_path_buf();
    let r = Image::from_fn(40, 30, |x, y| [x as f32 / 40.0 * 3.0, y as f32 / 30.0, 0.5]);
    let t =
        Image::from_fn(40, 30, |x, y| if (x + y) % 7 == 0 { [2.0, 0.1, 0.1] } else { r.get(x, y) });
    write_exr(&r, d.join("r.exr")).unwrap();
    write_exr(&t, d.join("t.exr")).unwrap();
    let c = compare_files(&d.join("r.exr"), &d.join("t.exr"), None, DEFAULT_PPD, 0.01).unwrap();
    assert_eq!(c.mode, FlipMode::Hdr, "EXR defaults to HDR-FLIP");
    assert_eq!(c.flip_mean, flip_hdr(&r, &t, DEFAULT_PPD).mean);
    assert_eq!(c.smape, smape(&t, &r, 0.01).mean);
    assert_eq!(c.psnr, psnr(&r, &t));
    assert!(c.flip_mean > 0.01 && c.exposures.is_some());
    let ldr =
        compare_files(&d.join("r.exr"), &d.join("t.exr"), Some(FlipMode::Ldr), 40.0, 0.01).unwrap();
    assert_eq!(ldr.flip_mean, flip_ldr(&r, &t, 40.0).mean);

    let args = CompareOptions {
        reference: d.join("r.exr"),
        test: d.join("t.exr"),
        mode: None,
        ppd: DEFAULT_PPD,
        map: Some(d.join("map.png")),
        json: true,
        eps: 0.01,
    };
    compare(&args).unwrap();
    let map = ::image::open(d.join("map.png")).unwrap().to_rgb8();
    assert_eq!(map.dimensions(), (40, 30));
    assert!(map.pixels().any(|p| p.0 != map.get_pixel(0, 0).0), "the map shows the differences");
}

#[test]
fn compare_reports_bad_inputs_by_name() {
    let tmp = dir("bad");
    let d = tmp.path().to_path_buf();
    write_png_srgb(&Image::filled(8, 8, [0.5; 3]), d.join("a.png")).unwrap();
    write_png_srgb(&Image::filled(9, 8, [0.5; 3]), d.join("b.png")).unwrap();
    let err = compare_files(&d.join("a.png"), &d.join("b.png"), None, DEFAULT_PPD, 0.01)
        .unwrap_err()
        .to_string();
    assert!(err.contains("a.png") && err.contains("b.png") && err.contains("same size"), "{err}");
    let err = format!(
        "{:#}",
        compare_files(&d.join("a.png"), &d.join("missing.png"), None, DEFAULT_PPD, 0.01)
            .unwrap_err()
    );
    assert!(err.contains("missing.png"), "{err}");
    let err = compare_files(&d.join("a.png"), &d.join("a.png"), None, -1.0, 0.01)
        .unwrap_err()
        .to_string();
    assert!(err.contains("ppd"), "{err}");
    // PNG holds sRGB: linear 0.5 is stored as byte 188 and read back as linear again.
    assert_eq!(::image::open(d.join("a.png")).unwrap().to_rgb8().get_pixel(0, 0).0, [188; 3]);
    assert!((load_image(d.join("a.png")).unwrap().get(0, 0)[0] - 0.5).abs() < 3e-3);
}
