//! The path-traced subsurface reference (the second reference): an analogue random walk in
//! a homogeneous half-space (z < 0, isotropic phase, index-matched boundary, f64 on the CPU),
//! tallying where light leaves the surface. It measures the diffusion model's own bias:
//! Burley's profile (with its A and d) against transport that does not approximate it, under a
//! searchlight (the profile's own definition) and under a point light over the slab.
//!
//! Its analytic limits (tests): the singly scattered fraction of a normally incident beam is
//! α(1 − ln 2)/2, and the whole reflectance is the plane albedo 1 − H(1)√(1 − α) with
//! Chandrasekhar's H-function of isotropic scattering ([`h_function`]).

use scene::SplitMix64;
use std::f64::consts::PI;

/// A homogeneous medium: scattering and absorption coefficients (per scene unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_s: f64,
    pub sigma_a: f64,
}

impl Medium {
    /// A medium of unit mean free path (σ_t = 1) and single-scattering albedo α.
    pub fn unit(alpha: f64) -> Self {
        Self { sigma_s: alpha, sigma_a: 1.0 - alpha }
    }

    pub fn sigma_t(&self) -> f64 {
        self.sigma_s + self.sigma_a
    }

    pub fn albedo(&self) -> f64 {
        self.sigma_s / self.sigma_t()
    }

    /// The diffuse mean free path 1/σ_tr, σ_tr = √(3 σ_a σ_t) (isotropic phase: σ_t' = σ_t),
    /// the ℓ_d of Burley's Θ3 parameterisation (eq. 2.44).
    pub fn diffuse_mean_free_path(&self) -> f64 {
        1.0 / (3.0 * self.sigma_a * self.sigma_t()).sqrt()
    }
}

/// Where light left the surface: exitance per radial bin, totals, and the singly scattered part.
#[derive(Clone, Debug, Default)]
pub struct ExitTally {
    pub bin_width: f64,
    /// Weight that left through annulus [k w, (k+1) w) (beyond the last bin: not binned).
    pub bins: Vec<f64>,
    /// Σ weight, and Σ weight² (for the standard error of the mean per path).
    pub total: f64,
    pub total_sq: f64,
    /// Weight that left after exactly one scattering event.
    pub single: f64,
    pub single_sq: f64,
    pub paths: u64,
}

impl ExitTally {
    pub fn new(bin_width: f64, bins: usize) -> Self {
        Self { bin_width, bins: vec![0.0; bins], ..Default::default() }
    }

    fn add(&mut self, r: f64, weight: f64, events: u32) {
        let k = (r / self.bin_width) as usize;
        if k < self.bins.len() {
            self.bins[k] += weight;
        }
        self.total += weight;
        self.total_sq += weight * weight;
        if events == 1 {
            self.single += weight;
            self.single_sq += weight * weight;
        }
    }

    /// Mean per path and its standard error, of (total, single).
    pub fn reflectance(&self) -> (f64, f64) {
        mean_and_error(self.total, self.total_sq, self.paths)
    }

    pub fn single_scattering(&self) -> (f64, f64) {
        mean_and_error(self.single, self.single_sq, self.paths)
    }

    /// The fraction of the binned exitance inside radius r (linear inside a bin).
    pub fn cdf(&self, r: f64) -> f64 {
        let all: f64 = self.bins.iter().sum();
        let k = (r / self.bin_width).floor() as usize;
        let below: f64 = self.bins.iter().take(k).sum();
        let part = self.bins.get(k).map_or(0.0, |b| b * (r / self.bin_width - k as f64));
        (below + part) / all.max(f64::MIN_POSITIVE)
    }
}

fn mean_and_error(sum: f64, sum_sq: f64, n: u64) -> (f64, f64) {
    let n = n.max(1) as f64;
    let mean = sum / n;
    let var = (sum_sq / n - mean * mean).max(0.0);
    (mean, (var / n).sqrt())
}

fn uniform(rng: &mut SplitMix64) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn isotropic(rng: &mut SplitMix64) -> [f64; 3] {
    let z = 2.0 * uniform(rng) - 1.0;
    let phi = 2.0 * PI * uniform(rng);
    let s = (1.0 - z * z).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

/// The most scattering events of one walk; a walk cut here is counted as absorbed (with
/// α ≤ 0.999 the weight surviving 10⁵ events is below e^{−100}).
pub const MAX_EVENTS: u32 = 100_000;

/// One analogue walk entering at `p` (z = 0) along `dir` (dir.z < 0): free flights
/// Exp(σ_t), scattering with probability α (isotropic), absorption otherwise; leaving through
/// z = 0 is tallied at its radius from `centre`.
fn walk(
    medium: &Medium,
    p: [f64; 3],
    dir: [f64; 3],
    centre: [f64; 2],
    rng: &mut SplitMix64,
    tally: &mut ExitTally,
) {
    if let Some(([x, y], events)) = walk_exit(medium, p, dir, rng) {
        let (x, y) = (x - centre[0], y - centre[1]);
        tally.add((x * x + y * y).sqrt(), 1.0, events);
    }
}

/// The walk itself: where it leaves through z = 0 and after how many scattering events, or
/// None when absorbed.
fn walk_exit(
    medium: &Medium,
    mut p: [f64; 3],
    mut dir: [f64; 3],
    rng: &mut SplitMix64,
) -> Option<([f64; 2], u32)> {
    let (sigma_t, alpha) = (medium.sigma_t(), medium.albedo());
    for events in 0..=MAX_EVENTS {
        let t = -(1.0 - uniform(rng)).ln() / sigma_t;
        let z = p[2] + t * dir[2];
        if z >= 0.0 {
            // Leaves through the surface at the crossing point.
            let s = -p[2] / dir[2];
            return Some(([p[0] + s * dir[0], p[1] + s * dir[1]], events));
        }
        p = [p[0] + t * dir[0], p[1] + t * dir[1], z];
        if uniform(rng) >= alpha {
            return None;
        }
        dir = isotropic(rng);
    }
    None
}

/// The searchlight's walks one by one: the exit offset (x, y) of each walk that leaves, and
/// how many walks were traced (the others were absorbed).
pub fn searchlight_exits(medium: &Medium, paths: u64, seed: u64) -> (Vec<[f64; 2]>, u64) {
    let mut rng = SplitMix64::seeded(seed);
    let exits = (0..paths)
        .filter_map(|_| walk_exit(medium, [0.0; 3], [0.0, 0.0, -1.0], &mut rng).map(|e| e.0))
        .collect();
    (exits, paths)
}

/// A normally incident pencil beam at the origin (the searchlight: R(r)'s definition).
pub fn searchlight(
    medium: &Medium,
    paths: u64,
    seed: u64,
    bin_width: f64,
    bins: usize,
) -> ExitTally {
    let mut rng = SplitMix64::seeded(seed);
    let mut tally = ExitTally::new(bin_width, bins);
    for _ in 0..paths {
        walk(medium, [0.0; 3], [0.0, 0.0, -1.0], [0.0, 0.0], &mut rng, &mut tally);
    }
    tally.paths = paths;
    tally
}

/// Where a photon of an isotropic point light at height h over the origin, emitted into the
/// lower hemisphere, meets the surface, and its direction: the irradiance is I cos θ / dist².
fn point_light_entry(height: f64, rng: &mut SplitMix64) -> ([f64; 3], [f64; 3]) {
    let cos = uniform(rng).max(1e-12);
    let phi = 2.0 * PI * uniform(rng);
    let sin = (1.0 - cos * cos).sqrt();
    let dir = [sin * phi.cos(), sin * phi.sin(), -cos];
    let s = height / cos;
    ([s * dir[0], s * dir[1], 0.0], dir)
}

/// An isotropic point light at `height` over the half-space: each photon of its lower
/// hemisphere enters where it hits (index-matched: no refraction) and walks.
pub fn point_light(
    medium: &Medium,
    height: f64,
    paths: u64,
    seed: u64,
    bin_width: f64,
    bins: usize,
) -> ExitTally {
    let mut rng = SplitMix64::seeded(seed);
    let mut tally = ExitTally::new(bin_width, bins);
    for _ in 0..paths {
        let (p, dir) = point_light_entry(height, &mut rng);
        walk(medium, p, dir, [0.0, 0.0], &mut rng, &mut tally);
    }
    tally.paths = paths;
    tally
}

/// The diffusion model's answer to the same point light: each photon leaves at a distance r
/// from where it entered drawn from Burley's radial density (shape d, numeric inverse) in a
/// uniform direction, with weight A: the screen-space pass's convolution of the irradiance
/// with R (eq. 5.2), estimated by the same tally.
pub fn point_light_burley(
    albedo: f64,
    d: f64,
    height: f64,
    paths: u64,
    seed: u64,
    bin_width: f64,
    bins: usize,
) -> ExitTally {
    let mut rng = SplitMix64::seeded(seed);
    let mut tally = ExitTally::new(bin_width, bins);
    for _ in 0..paths {
        let (p, _) = point_light_entry(height, &mut rng);
        let r = sss::inverse::numeric_inverse(uniform(&mut rng).min(1.0 - 1e-12), d);
        let phi = 2.0 * PI * uniform(&mut rng);
        let (x, y) = (p[0] + r * phi.cos(), p[1] + r * phi.sin());
        tally.add((x * x + y * y).sqrt(), albedo, 2);
    }
    tally.paths = paths;
    tally
}

/// Chandrasekhar's H-function of isotropic scattering with albedo α at μ, from
/// 1/H(μ) = √(1 − α) + (α/2) ∫_0^1 μ' H(μ') / (μ + μ') dμ' (the alternative form of H's equation),
/// iterated to a fixed point on 64 Gauss-Legendre nodes and then evaluated at μ. α < 1: at
/// α = 1 this form's iteration does not settle (measured: ∫H came out 4.43, not 2).
pub fn h_function(alpha: f64, mu: f64) -> f64 {
    assert!((0.0..1.0).contains(&alpha), "H-function albedo {alpha}; expected [0, 1)");
    let (nodes, weights) = gauss_legendre_unit(64);
    let mut h = vec![1.0; nodes.len()];
    let at = |h: &[f64], m: f64| {
        1.0 / ((1.0 - alpha).sqrt()
            + 0.5
                * alpha
                * nodes
                    .iter()
                    .zip(&weights)
                    .zip(h)
                    .map(|((x, w), hx)| w * x * hx / (m + x))
                    .sum::<f64>())
    };
    for _ in 0..2000 {
        let next: Vec<f64> = nodes.iter().map(|&m| at(&h, m)).collect();
        let change = next.iter().zip(&h).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        h = next;
        if change < 1e-14 {
            break;
        }
    }
    at(&h, mu)
}

/// The plane albedo of the half-space for a beam at cosine μ0: 1 − H(μ0) √(1 − α).
pub fn plane_albedo(alpha: f64, mu0: f64) -> f64 {
    1.0 - h_function(alpha, mu0) * (1.0 - alpha).sqrt()
}

/// Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n, Numerical Recipes §4.6).
pub fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, 0.0);
            for j in 0..n {
                let p2 = p1;
                p1 = p0;
                p0 = ((2 * j + 1) as f64 * z * p1 - j as f64 * p2) / (j + 1) as f64;
            }
            dp = n as f64 * (z * p0 - p1) / (z * z - 1.0);
            let step = p0 / dp;
            z -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        // Map [−1, 1] → [0, 1].
        x[i] = 0.5 * (1.0 - z);
        x[n - 1 - i] = 0.5 * (1.0 + z);
        w[i] = 0.5 * wi;
        w[n - 1 - i] = 0.5 * wi;
    }
    (x, w)
}
