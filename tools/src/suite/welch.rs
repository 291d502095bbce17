//! Welch's unequal-variance t-test, one-sided, against a margin: is the new mean worse than
//! the baseline mean by more than `margin`? Seeds are independent draws, the two groups may have
//! different sizes and spreads, so Welch's test rather than Student's pooled one.

use super::student_t;

/// Mean, sample variance (n - 1) and size of one group of per-seed values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub mean: f64,
    pub variance: f64,
    pub n: usize,
}

impl Sample {
    pub fn of(values: &[f64]) -> Sample {
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n as f64;
        let variance = if n > 1 {
            values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        Sample { mean, variance, n }
    }

    /// Standard error of the mean.
    pub fn standard_error(&self) -> f64 {
        (self.variance / self.n as f64).sqrt()
    }
}

/// The test of H0: new - baseline <= margin against H1: new - baseline > margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Welch {
    /// new mean - baseline mean.
    pub difference: f64,
    /// Standard error of the difference.
    pub standard_error: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub df: f64,
    pub t: f64,
    /// P(T >= t) under H0: small means "worse by more than the margin".
    pub p_value: f64,
}

impl Welch {
    /// Whether H0 is rejected at `confidence` (e.g. 0.95): the regression is real.
    pub fn worse(&self, confidence: f64) -> bool {
        self.p_value < 1.0 - confidence
    }
}

pub fn one_sided(new: &Sample, baseline: &Sample, margin: f64) -> Welch {
    let (a, b) = (new.variance / new.n as f64, baseline.variance / baseline.n as f64);
    let se2 = a + b;
    let difference = new.mean - baseline.mean;
    let excess = difference - margin;
    if se2 <= 0.0 {
        // No spread in either group (a deterministic adapter, the same seeds): the difference is
        // known exactly.
        let p_value = if excess > 0.0 { 0.0 } else { 1.0 };
        return Welch {
            difference,
            standard_error: 0.0,
            df: f64::INFINITY,
            t: if excess > 0.0 { f64::INFINITY } else { f64::NEG_INFINITY },
            p_value,
        };
    }
    let term = |v: f64, n: usize| if n > 1 { v * v / (n - 1) as f64 } else { 0.0 };
    let df = se2 * se2 / (term(a, new.n) + term(b, baseline.n)).max(f64::MIN_POSITIVE);
    let t = excess / se2.sqrt();
    Welch { difference, standard_error: se2.sqrt(), df, t, p_value: 1.0 - student_t::cdf(t, df) }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Welch's t and df of these two groups by the textbook formulas in Python's `statistics`,
    // and the p-value by Simpson integration of the t density from t to 2000 (200000 steps):
    // t = 3.46410, df = 6.96870, p = 0.0052818.
    #[test]
    fn matches_an_independent_computation() {
        let new = Sample::of(&[20.1, 22.4, 19.8, 21.7, 23.0]);
        let base = Sample::of(&[18.2, 19.9, 17.5, 18.8]);
        let w = one_sided(&new, &base, 0.0);
        assert!((w.t - 3.46410).abs() < 1e-4, "t = {}", w.t);
        assert!((w.df - 6.96870).abs() < 1e-4, "df = {}", w.df);
        assert!((w.p_value - 0.0052818).abs() < 1e-6, "p = {}", w.p_value);
        assert!(w.worse(0.95));
        // A margin above the difference is not a regression.
        assert!(!one_sided(&new, &base, 3.0).worse(0.95));
    }

    #[test]
    fn no_spread_compares_the_means_exactly() {
        let same = Sample::of(&[0.3, 0.3, 0.3]);
        assert!(!one_sided(&same, &same, 0.0).worse(0.95));
        let worse = Sample::of(&[0.4, 0.4, 0.4]);
        assert!(one_sided(&worse, &same, 0.05).worse(0.95));
        assert!(!one_sided(&worse, &same, 0.2).worse(0.95));
    }
}
