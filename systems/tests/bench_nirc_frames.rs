//! The Table 1 bench plays whole frames of each predictor and keeps every timed frame (its
//! numbers are timings, so nothing here compares them).

use systems::bench_nirc_frames::{PREDICTORS, run};

#[test]
fn plays_every_predictor_and_keeps_each_timed_frame() {
    let scratch = std::env::temp_dir().join(format!("flicker-test-nirc-frames-{}", std::process::id()));
    let t = run((16, 9), 1, 2, &scratch).expect("the frame bench runs on the test adapter");
    assert!(!scratch.exists(), "the scratch folder is removed");
    let names: Vec<&str> = t.rows.iter().map(|r| r.predictor.as_str()).collect();
    assert_eq!(names, PREDICTORS);
    for r in &t.rows {
        assert_eq!(r.frame_ms.len(), 2, "{}", r.predictor);
        assert!(r.frame_ms.iter().all(|ms| ms.is_finite() && *ms > 0.0), "{}: {:?}", r.predictor, r.frame_ms);
        let passes: Vec<&str> = r.pass_ms.iter().map(|(p, _)| p.as_str()).collect();
        for p in ["nirc_paths", "nirc_infer", "nirc_train", "nirc_ema"] {
            assert!(passes.contains(&p), "{}: {passes:?} lacks {p}", r.predictor);
        }
        // A frame is the sum of its passes.
        let sum: f64 = r.pass_ms.iter().map(|(_, ms)| ms).sum();
        assert!((sum - r.ms_per_frame).abs() < 1e-9 * sum.max(1.0), "{}: {sum} against {}", r.predictor, r.ms_per_frame);
    }
    assert!(t.blend_overhead_frame_percent.is_finite() && t.blend_overhead_frame_percent_ci95.0 <= t.blend_overhead_frame_percent);
}
