//! Relations between methods over seeds: the per-seed differences' mean above zero with 95%
//! confidence (one-sided Student t), the margin taken from the spread across seeds.

/// One-sided 95% Student t quantiles for 2 to 6 degrees of freedom (3 to 7 seeds).
const T95: [f64; 5] = [2.920, 2.353, 2.132, 2.015, 1.943];

/// Asserts that the mean of per-seed differences `d` is above zero with 95% confidence.
pub fn assert_positive(what: &str, d: &[f64]) {
    assert!((3..=7).contains(&d.len()), "{what}: {} seeds; expected 3 to 7", d.len());
    let n = d.len() as f64;
    let m = d.iter().sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)).sqrt();
    let lower = m - T95[d.len() - 3] * sd / n.sqrt();
    eprintln!("{what}: per seed {d:.4?}, mean {m:.4}, lower 95% bound {lower:.4}");
    assert!(
        lower > 0.0,
        "{what}: per-seed differences {d:.4?}, mean {m:.4}, one-sided 95% lower bound {lower:.4} is not above 0"
    );
}
