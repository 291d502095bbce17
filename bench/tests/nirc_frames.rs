//! The Table 1 bench plays whole frames of each predictor and keeps every timed frame (its
//! numbers are timings, so nothing here compares them).

use bench::nirc_frames::{PREDICTORS, run};

#[test]
fn plays_every_predictor_and_keeps_each_timed_frame() {
    let scratch =
        std::env::temp_dir().join(format!("flicker-test-nirc-frames-{}", std::process::id()));
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
    let (lo, hi) = t.blend_overhead_frame_percent_ci95;
    assert!(
        lo.is_finite()
            && hi.is_finite()
            && lo <= t.blend_overhead_frame_percent
            && t.blend_overhead_frame_percent <= hi,
        "{lo} {} {hi}",
        t.blend_overhead_frame_percent
    );
}
