//! Sec. 4.1 on a 1-D extinction profile over [0, t_max]: stratified jittered sampling (one
//! independent jitter per stratum) against i.i.d. uniform sampling, each X = t_max/N Σ μ(t_j).

use crate::rng::Pcg;

pub fn stratified_jittered(mu: impl Fn(f32) -> f32, t_max: f32, n: u32, rng: &mut Pcg) -> f32 {
    let sum: f32 = (0..n).map(|j| mu((j as f32 + rng.next_f32()) / n as f32 * t_max)).sum();
    sum * t_max / n as f32
}

pub fn iid_uniform(mu: impl Fn(f32) -> f32, t_max: f32, n: u32, rng: &mut Pcg) -> f32 {
    let sum: f32 = (0..n).map(|_| mu(rng.next_f32() * t_max)).sum();
    sum * t_max / n as f32
}
