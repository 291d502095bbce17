//! Optical depth by ray marching with importance sampling over the super-voxel grid: the
//! paper's Alg. 2 (integral of importance F and the tight segment) and Alg. 1 (m i.i.d.
//! estimates X_0..X_{m−1} from one traversal, N samples each, one high-resolution lookup per
//! pass of the outer loop).
//!
//! Two importances: Kettunen et al.'s mean (no control variate) and the paper's variance-aware
//! RMS of μ − μ_min (Eq. 5) with μ_min as control variate τ_c, tracked exactly. Two jitters:
//! stratified (each sample its own rand(), the paper's) and uniform (one rand() per estimate,
//! Kettunen et al.'s).
//!
//! Erratum applied: Alg. 1 prints `I_j := ceil(I_j) + rand()`, which repeats a stratum when
//! rand() returns exactly 0 (our rand() can); we use floor(I_j) + 1 + rand().

use crate::dda::Dda;
use crate::medium::{Medium, Segment};
use crate::rng::Pcg;
use crate::supervoxel::SuperVoxel;

/// Estimates one call produces at most: unbiased ray marching with power-series degree ≤ 8.
pub const MAX_ESTIMATES: usize = 9;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Importance {
    /// Kettunen et al. 2021: the super-voxel mean, no control variate.
    Mean,
    /// The paper's Eq. 5 with the super-voxel minimum as control variate.
    VarianceAware,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Jitter {
    Stratified,
    Uniform,
}

impl Importance {
    /// (P, μ_min) of a super-voxel.
    fn of(self, sv: &SuperVoxel) -> (f32, f32) {
        match self {
            Importance::Mean => (sv.mean, 0.0),
            Importance::VarianceAware => (sv.variance_importance(), sv.min),
        }
    }
}

/// Samples N per estimate: fixed (the paper's choice, Sec. 4.3: F_Δ = F / N) or tied to the
/// importance along the ray (Fig. 8d: F_Δ = `step` set manually, N = ceil(F / step), at least 1
/// and at most [`MAX_TIED_SAMPLES`], so that a shader's loop stays bounded).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleCount {
    Fixed(u32),
    PerImportance { step: f32 },
}

/// The most samples per estimate of an importance-tied count.
pub const MAX_TIED_SAMPLES: u32 = 64;

impl SampleCount {
    /// N for a ray whose integral of importance (Alg. 2) is `total`.
    pub fn count(self, total: f32) -> u32 {
        match self {
            SampleCount::Fixed(n) => n,
            SampleCount::PerImportance { step } => tied_sample_count(total, step),
        }
    }
}

/// ceil(F / F_Δ) clamped to [1, MAX_TIED_SAMPLES] (media_optical_depth.wgsl's twin).
pub fn tied_sample_count(total: f32, step: f32) -> u32 {
    ((total / step).ceil().min(MAX_TIED_SAMPLES as f32) as u32).max(1)
}

/// Alg. 2's output: F and the tight segment [t_min, t_max] of non-empty importance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prepared {
    pub total: f32,
    pub t_min: f32,
    pub t_max: f32,
}

/// Alg. 2: regular tracking of the super-voxel grid.
pub fn prepare(medium: &Medium, seg: &Segment, importance: Importance) -> Prepared {
    let mut dda = Dda::new(seg, medium.super_voxels.dims, medium.super_voxel_size());
    let mut out = Prepared { total: 0.0, t_min: seg.t1, t_max: seg.t0 };
    let mut t = seg.t0;
    loop {
        let (p, _) = importance.of(medium.super_voxels.cell(dda.ucell()));
        let exit = dda.exit();
        out.total += (exit - t) * p;
        if p != 0.0 {
            out.t_min = out.t_min.min(t);
            out.t_max = out.t_max.max(exit);
        }
        t = exit;
        if !dda.advance() {
            return out;
        }
    }
}

/// Alg. 1: `count` (≤ MAX_ESTIMATES) i.i.d. estimates of the optical depth of `seg` into
/// `out[..count]`, `samples` (N) each; returns the number of density lookups (count · N).
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    medium: &Medium,
    seg: &Segment,
    prep: &Prepared,
    count: usize,
    samples: u32,
    importance: Importance,
    jitter: Jitter,
    rng: &mut Pcg,
    out: &mut [f32; MAX_ESTIMATES],
) -> u32 {
    *out = [0.0; MAX_ESTIMATES];
    // I_k: the CDF at each estimate's next sample, divided by F_Δ; unused estimates never win.
    let mut i_next = [f32::MAX; MAX_ESTIMATES];
    for i in i_next.iter_mut().take(count) {
        *i = rng.next_f32();
    }
    if prep.total <= 0.0 {
        return 0; // F = 0: nothing along the ray (Sec. 4.3).
    }
    let f_delta = prep.total / samples as f32;
    let tight = Segment { t0: prep.t_min, t1: prep.t_max, ..*seg };
    let mut dda = Dda::new(&tight, medium.super_voxels.dims, medium.super_voxel_size());
    let (mut p, mut mu_min) = importance.of(medium.super_voxels.cell(dda.ucell()));
    let mut t_exit = dda.exit();
    let mut f = (t_exit - tight.t0) * p;
    let mut tau_c = (t_exit - tight.t0) * mu_min;
    let mut exhausted = false;
    let mut j = arg_min(&i_next);
    let mut lookups = 0;
    // Bounded: one sample or the end per pass, plus the cells of the traversal.
    let dims = medium.super_voxels.dims;
    for _ in 0..(count as u32 * samples + dims.x + dims.y + dims.z + 2) {
        if f_delta * i_next[j] >= f && exhausted {
            break;
        }
        // Advance over super-voxels until the CDF passes the next sample (or the segment ends).
        while f_delta * i_next[j] >= f && !exhausted {
            if !dda.advance() {
                exhausted = true;
                break;
            }
            let (p_new, min_new) = importance.of(medium.super_voxels.cell(dda.ucell()));
            let t_enter = t_exit;
            t_exit = dda.exit();
            p = p_new;
            mu_min = min_new;
            f += (t_exit - t_enter) * p;
            tau_c += (t_exit - t_enter) * mu_min;
        }
        if f_delta * i_next[j] < f {
            // Rewind to the sample inside the current super-voxel.
            let t = t_exit - (f - f_delta * i_next[j]) / p;
            out[j] += (medium.mu(&tight, t, dda.ucell()) - mu_min) / p;
            lookups += 1;
            i_next[j] = match jitter {
                Jitter::Stratified => i_next[j].floor() + 1.0 + rng.next_f32(),
                Jitter::Uniform => i_next[j] + 1.0,
            };
            j = arg_min(&i_next);
        }
    }
    for x in out.iter_mut().take(count) {
        *x = f_delta * *x + tau_c;
    }
    lookups
}

fn arg_min(values: &[f32; MAX_ESTIMATES]) -> usize {
    let mut j = 0;
    for k in 1..MAX_ESTIMATES {
        if values[k] < values[j] {
            j = k;
        }
    }
    j
}

/// Kettunen et al. 2021's ray-marching sample count for a control optical depth: the
/// cube root of a cubic with roots −0.015, −0.65, −60.3, divided by 1 + N_BK (N_BK = 0.31945),
/// times `multiplier` (the paper doubles it for biased ray marching).
pub fn kettunen_sample_count(control_optical_depth: f32, multiplier: f32) -> u32 {
    let x = control_optical_depth;
    // powf(1/3), not cbrt: the WGSL twin has only pow, and the ceil must agree.
    let n_cmf = ((x + 0.015) * (x + 0.65) * (x + 60.3)).powf(1.0 / 3.0).ceil();
    ((multiplier * n_cmf / (1.0 + 0.31945)).round() as u32).max(1)
}
