//! Shared by the media tests: seeded normal samples, a running mean/variance, complex numbers.
#![allow(dead_code)]

use media::Estimator;

#[allow(unused_imports)]
pub use media::rng::normal_f64 as normal;

/// Mean, variance and the standard errors of both, from sums of powers.
#[derive(Default, Clone, Copy, Debug)]
pub struct Moments {
    n: f64,
    s1: f64,
    s2: f64,
    s3: f64,
    s4: f64,
}

impl Moments {
    pub fn add(&mut self, x: f64) {
        self.n += 1.0;
        self.s1 += x;
        self.s2 += x * x;
        self.s3 += x * x * x;
        self.s4 += x * x * x * x;
    }
    pub fn mean(&self) -> f64 {
        self.s1 / self.n
    }
    pub fn var(&self) -> f64 {
        (self.s2 / self.n - self.mean().powi(2)) * self.n / (self.n - 1.0)
    }
    pub fn std(&self) -> f64 {
        self.var().sqrt()
    }
    /// Standard error of the mean.
    pub fn se(&self) -> f64 {
        (self.var() / self.n).sqrt()
    }
    /// Standard error of the variance: sqrt((m4 − σ⁴) / n) with the central fourth moment m4.
    pub fn var_se(&self) -> f64 {
        let m = self.mean();
        let n = self.n;
        let m4 = self.s4 / n - 4.0 * m * self.s3 / n + 6.0 * m * m * self.s2 / n - 3.0 * m.powi(4);
        ((m4 - self.var().powi(2)) / n).sqrt()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct C {
    pub re: f64,
    pub im: f64,
}

impl C {
    pub fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    pub fn mul(self, o: C) -> C {
        C::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
    pub fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)
    }
    pub fn exp(self) -> C {
        let e = self.re.exp();
        C::new(e * self.im.cos(), e * self.im.sin())
    }
    pub fn scale(self, k: f64) -> C {
        C::new(self.re * k, self.im * k)
    }
    pub fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    pub fn sinh(self) -> C {
        self.exp().add(self.scale(-1.0).exp().scale(-1.0)).scale(0.5)
    }
}

/// Every estimator, with the settings the tests use.
pub fn all_estimators() -> [Estimator; 6] {
    [
        Estimator::TrackLength,
        Estimator::RatioTracking,
        Estimator::BiasedRayMarching { multiplier: 2.0 },
        Estimator::UnbiasedRayMarching { multiplier: 1.0 },
        Estimator::Naive { samples: 16 },
        Estimator::Jackknife { samples: 8 },
    ]
}

/// Least-squares slope of log y against log x.
pub fn log_slope(x: &[f64], y: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let cov: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let var: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    cov / var
}
