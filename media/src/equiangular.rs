//! Equiangular sampling of a point light along a ray (Kulla and Fajardo 2012): the density
//! p0(t) ∝ 1 / (D² + (t − Δ)²) on [a, b], D the light's distance from the ray's line and Δ the
//! ray parameter of its foot point, sampled by inverting the angle θ = atan((t − Δ)/D).

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equiangular {
    /// Ray parameter of the light's foot point on the ray.
    pub delta: f32,
    /// Distance of the light from the ray's line (> 0).
    pub d: f32,
    pub theta_a: f32,
    pub theta_b: f32,
}

impl Equiangular {
    /// For the part [a, b] of a ray from `origin` along unit `dir`, towards a light at `light`.
    pub fn new(origin: Vec3, dir: Vec3, light: Vec3, a: f32, b: f32) -> Self {
        let delta = (light - origin).dot(dir);
        let d = (light - origin - delta * dir).length().max(1e-6);
        Self::from_foot(delta, d, a, b)
    }

    pub fn from_foot(delta: f32, d: f32, a: f32, b: f32) -> Self {
        Self { delta, d, theta_a: ((a - delta) / d).atan(), theta_b: ((b - delta) / d).atan() }
    }

    pub fn sample(&self, xi: f32) -> f32 {
        self.delta + self.d * (self.theta_a + xi * (self.theta_b - self.theta_a)).tan()
    }

    pub fn pdf(&self, t: f32) -> f32 {
        let x = t - self.delta;
        self.d / ((self.theta_b - self.theta_a) * (self.d * self.d + x * x))
    }
}
