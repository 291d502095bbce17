//! Reynolds' boids: separation, alignment and cohesion inside an axis-aligned box.
//!
//! Steering follows Reynolds (1987); on top of it a position projection (as in
//! position-based dynamics) enforces the minimum separation and the box exactly, so the
//! flock never interpenetrates or leaves its box whatever the weights.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::resources::Clock;
use crate::rng::Rng;
use crate::transform::Transform;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlockParams {
    pub bounds_min: Vec3,
    pub bounds_max: Vec3,
    /// Hard minimum distance between two boids' centres (metres).
    pub separation: f32,
    /// Radius within which boids see each other for alignment and cohesion.
    pub view_radius: f32,
    pub separation_weight: f32,
    pub alignment_weight: f32,
    pub cohesion_weight: f32,
    pub min_speed: f32,
    pub max_speed: f32,
}

impl Default for FlockParams {
    fn default() -> Self {
        Self {
            bounds_min: Vec3::new(-2.0, 0.5, -2.0),
            bounds_max: Vec3::new(2.0, 3.0, 2.0),
            separation: 0.3,
            view_radius: 1.0,
            separation_weight: 1.5,
            alignment_weight: 1.0,
            cohesion_weight: 0.6,
            min_speed: 0.5,
            max_speed: 2.0,
        }
    }
}

/// On the flock's (hidden) prototype entity.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Flock {
    pub params: FlockParams,
}

/// One member of a flock.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Boid {
    pub flock: Entity,
    /// Position in the flock's update order.
    pub index: u32,
    pub velocity: Vec3,
}

/// Initial positions (at least `separation` apart when the box allows it) and velocities.
pub fn initial_boids(params: &FlockParams, count: u32, rng: &mut Rng) -> Vec<(Vec3, Vec3)> {
    let (lo, hi) = (params.bounds_min, params.bounds_max);
    let mut out: Vec<(Vec3, Vec3)> = Vec::with_capacity(count as usize);
    for _ in 0..count {
        let mut p = Vec3::ZERO;
        for _attempt in 0..200 {
            p = Vec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z));
            if out.iter().all(|(q, _)| q.distance(p) >= params.separation) {
                break;
            }
        }
        let speed = 0.5 * (params.min_speed + params.max_speed);
        out.push((p, rng.unit_vector() * speed));
    }
    out
}

/// One fixed step of the flock: steering, integration, then projection onto the
/// constraints (minimum separation, inside the box).
pub fn step_flock(params: &FlockParams, positions: &mut [Vec3], velocities: &mut [Vec3], dt: f32) {
    let n = positions.len();
    let (lo, hi) = (params.bounds_min, params.bounds_max);
    let margin = (0.2 * (hi - lo).min_element()).max(1e-3);
    let mut accel = vec![Vec3::ZERO; n];
    for i in 0..n {
        let (mut sep, mut vel_sum, mut pos_sum, mut seen) =
            (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0u32);
        for j in 0..n {
            if i == j {
                continue;
            }
            let d = positions[i] - positions[j];
            let dist = d.length();
            if dist < params.view_radius {
                vel_sum += velocities[j];
                pos_sum += positions[j];
                seen += 1;
                if dist < 2.0 * params.separation {
                    // Inverse-distance push, strongest when close.
                    sep += d / dist.max(1e-4).powi(2);
                }
            }
        }
        let mut a = params.separation_weight * sep;
        if seen > 0 {
            let inv = 1.0 / seen as f32;
            a += params.alignment_weight * (vel_sum * inv - velocities[i]);
            a += params.cohesion_weight * (pos_sum * inv - positions[i]);
        }
        // Turn back before the walls.
        let p = positions[i];
        for k in 0..3 {
            if p[k] < lo[k] + margin {
                a[k] += params.max_speed * (lo[k] + margin - p[k]) / margin * 4.0;
            }
            if p[k] > hi[k] - margin {
                a[k] -= params.max_speed * (p[k] - (hi[k] - margin)) / margin * 4.0;
            }
        }
        accel[i] = a;
    }
    for i in 0..n {
        let mut v = velocities[i] + accel[i] * dt;
        let speed = v.length();
        if speed > params.max_speed {
            v *= params.max_speed / speed;
        } else if speed < params.min_speed {
            v = if speed > 1e-6 {
                v * (params.min_speed / speed)
            } else {
                Vec3::X * params.min_speed
            };
        }
        velocities[i] = v;
        positions[i] += v * dt;
    }
    project_constraints(params, positions, velocities);
}

/// Pushes overlapping pairs apart and clamps into the box until both hold (Gauss-Seidel).
fn project_constraints(params: &FlockParams, positions: &mut [Vec3], velocities: &mut [Vec3]) {
    let n = positions.len();
    let d_min = params.separation;
    for _ in 0..64 {
        let mut violated = false;
        for i in 0..n {
            for j in (i + 1)..n {
                let d = positions[i] - positions[j];
                let dist = d.length();
                if dist < d_min * (1.0 - 1e-4) {
                    violated = true;
                    // Deterministic direction when two boids coincide.
                    let dir = if dist > 1e-6 { d / dist } else { Vec3::new(1.0, 0.0, 0.0) };
                    let push = 0.5 * (d_min - dist) * 1.001;
                    positions[i] += dir * push;
                    positions[j] -= dir * push;
                }
            }
        }
        for (p, v) in positions.iter_mut().zip(velocities.iter_mut()) {
            for k in 0..3 {
                if p[k] < params.bounds_min[k] {
                    p[k] = params.bounds_min[k];
                    v[k] = v[k].abs();
                } else if p[k] > params.bounds_max[k] {
                    p[k] = params.bounds_max[k];
                    v[k] = -v[k].abs();
                }
            }
        }
        if !violated {
            break;
        }
    }
}

/// Orientation that points a mesh modelled along -Z in the direction of flight.
pub fn heading(velocity: Vec3) -> Quat {
    let dir = velocity.normalize_or(Vec3::NEG_Z);
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    Transform::looking_at(Vec3::ZERO, dir, up).rotation
}

pub fn flock(
    clock: Res<Clock>,
    flocks: Query<(Entity, &Flock)>,
    mut boids: Query<(&mut Boid, &mut Transform)>,
) {
    let dt = clock.delta();
    if dt == 0.0 {
        return;
    }
    for (flock_entity, flock) in &flocks {
        let mut members: Vec<(u32, Vec3, Vec3)> = boids
            .iter()
            .filter(|(b, _)| b.flock == flock_entity)
            .map(|(b, t)| (b.index, t.translation, b.velocity))
            .collect();
        members.sort_by_key(|m| m.0);
        let mut positions: Vec<Vec3> = members.iter().map(|m| m.1).collect();
        let mut velocities: Vec<Vec3> = members.iter().map(|m| m.2).collect();
        step_flock(&flock.params, &mut positions, &mut velocities, dt);
        for (mut b, mut t) in &mut boids {
            if b.flock != flock_entity {
                continue;
            }
            let k = members.binary_search_by_key(&b.index, |m| m.0).unwrap();
            b.velocity = velocities[k];
            t.translation = positions[k];
            t.rotation = heading(velocities[k]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boids_stay_in_box_and_apart_over_many_steps() {
        let params = FlockParams::default();
        let mut rng = Rng::seeded(42);
        let init = initial_boids(&params, 40, &mut rng);
        let mut p: Vec<Vec3> = init.iter().map(|b| b.0).collect();
        let mut v: Vec<Vec3> = init.iter().map(|b| b.1).collect();
        let mut moved = 0.0;
        for step in 0..600 {
            let before = p.clone();
            step_flock(&params, &mut p, &mut v, 1.0 / 30.0);
            moved += before.iter().zip(&p).map(|(a, b)| a.distance(*b)).sum::<f32>();
            for (i, a) in p.iter().enumerate() {
                let eps = Vec3::splat(1e-5);
                assert!(
                    a.cmpge(params.bounds_min - eps).all()
                        && a.cmple(params.bounds_max + eps).all(),
                    "step {step}: boid {i} left the box at {a}"
                );
                for (j, b) in p.iter().enumerate().skip(i + 1) {
                    let d = a.distance(*b);
                    assert!(
                        d >= params.separation * 0.999,
                        "step {step}: boids {i},{j} only {d} apart"
                    );
                }
            }
        }
        // They fly: at least the minimum speed on average.
        assert!(moved / (40.0 * 600.0) >= params.min_speed / 30.0 * 0.5, "flock barely moved");
    }

    #[test]
    fn flocking_aligns_velocities() {
        // With alignment alone, the spread of headings shrinks.
        let params = FlockParams {
            separation_weight: 0.0,
            cohesion_weight: 0.0,
            alignment_weight: 4.0,
            view_radius: 10.0,
            ..Default::default()
        };
        let mut rng = Rng::seeded(5);
        let init = initial_boids(&params, 20, &mut rng);
        let mut p: Vec<Vec3> = init.iter().map(|b| b.0).collect();
        let mut v: Vec<Vec3> = init.iter().map(|b| b.1).collect();
        let order =
            |v: &[Vec3]| v.iter().map(|x| x.normalize()).sum::<Vec3>().length() / v.len() as f32;
        let before = order(&v);
        for _ in 0..30 {
            step_flock(&params, &mut p, &mut v, 1.0 / 60.0);
        }
        assert!(order(&v) > before + 0.2, "polarisation {} -> {}", before, order(&v));
    }
}
