//! The Table 1 bench plays whole frames of each predictor and keeps every timed frame (its
//! numbers are timings, so nothing here compares them).

use bench::nirc_frames::{PREDICTORS, run};

#[test]
fn plays_every_predictor_and_keeps_each_timed_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let scratch = tmp.path().join("scratch");
    let t = run((16, 9), 1, 2, &scratch).expect("the frame bench runs on the test adapter");
    assert!(!scratch.exists(), "the scratch folder is removed");
    let names: Vec<&str> = t.rows.iter().map(|r| r.predictor.as_str()).collect();
    assert_eq!(names, PREDICTORS);
    for r in &t.rows {
        assert!(
            r.frame_ms.iter().all(|ms| ms.is_finite() && *ms > 0.0),
            "{}: {:?}",
            r.predictor,
            r.frame_ms
        );
        let passes: Vec<&str> = r.pass_ms.iter().map(|(p, _)| p.as_str()).collect();
        for p in ["nirc_paths", "nirc_infer", "nirc_train", "nirc_ema"] {
            assert!(passes.contains(&p), "{}: {passes:?} lacks {p}", r.predictor);
        }
        // A frame is the sum of its passes: this fails if some frame lacks a pass the first has.
        let sum: f64 = r.pass_ms.iter().map(|(_, ms)| ms).sum();
        assert!(
            (sum - r.ms_per_frame).abs() < 1e-9 * sum.max(1.0),
            "{}: {sum} against {}",
            r.predictor,
            r.ms_per_frame
        );
    }
    // The overhead and its interval recomputed from the timed frames, independently of the
    // bench's code: the mean of paired differences is the difference of the means, and with two
    // frames the 95% half-width is t(0.975, 1 df) = 12.7062 (a table value) times the standard
    // error |d1 - d2| / 2.
    let (ema, blend) = (&t.rows[1], &t.rows[2]);
    assert_eq!((ema.frame_ms.len(), blend.frame_ms.len()), (2, 2));
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let percent = |ms: f64| 100.0 * ms / mean(&ema.frame_ms);
    let d: Vec<f64> = blend.frame_ms.iter().zip(&ema.frame_ms).map(|(b, e)| b - e).collect();
    let (overhead, half) = (mean(&d), 12.7062 * (d[0] - d[1]).abs() / 2.0);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-4 * b.abs().max(1e-3);
    let (lo, hi) = t.blend_overhead_frame_percent_ci95;
    assert!(
        close(t.blend_overhead_frame_percent, percent(overhead))
            && close(lo, percent(overhead - half))
            && close(hi, percent(overhead + half)),
        "bench: {} in [{lo}, {hi}]; from the frames: {} in [{}, {}]",
        t.blend_overhead_frame_percent,
        percent(overhead),
        percent(overhead - half),
        percent(overhead + half)
    );
}
