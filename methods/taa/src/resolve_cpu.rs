//! The TAA resolve of shaders/resolve.wgsl on the CPU, operation for operation, to
//! check the GPU pass (reprojection, rejection, clamp, blend) in tests.

use super::{TaaClamp, TaaPrimary, TaaSettings};
use glam::{IVec2, Vec2, Vec3};
use render::path_tracer::NO_HIT;

/// Resolves one frame: `current` colours and `primary` attributes of this frame, the previous
/// frame's `previous_primary` and `history` (w = history length). Returns rgb + new length.
pub fn resolve(
    settings: &TaaSettings,
    size: (u32, u32),
    history_valid: bool,
    current: &[[f32; 4]],
    primary: &[TaaPrimary],
    previous_primary: &[TaaPrimary],
    history: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let (w, h) = (size.0 as i32, size.1 as i32);
    let at = |q: IVec2| (q.y * w + q.x) as usize;
    let rgb = |c: [f32; 4]| Vec3::new(c[0], c[1], c[2]);
    let matches = |p: &TaaPrimary, q: IVec2| {
        let hp = &previous_primary[at(q)];
        if hp.instance != p.instance {
            return false;
        }
        if p.instance == NO_HIT {
            return true;
        }
        if (hp.depth - p.previous_depth).abs() > settings.depth_tolerance * p.previous_depth {
            return false;
        }
        Vec3::from(hp.normal).dot(Vec3::from(p.normal)) >= settings.normal_threshold
    };
    let bilinear = |pos: Vec2| {
        let st = pos - 0.5;
        let base = st.floor();
        let f = st - base;
        let b = base.as_ivec2();
        let hi = IVec2::new(w - 1, h - 1);
        let tap = |o: IVec2| rgb(history[at((b + o).clamp(IVec2::ZERO, hi))]);
        let top = tap(IVec2::new(0, 0)).lerp(tap(IVec2::new(1, 0)), f.x);
        let bottom = tap(IVec2::new(0, 1)).lerp(tap(IVec2::new(1, 1)), f.x);
        top.lerp(bottom, f.y)
    };
    let mut out = Vec::with_capacity(current.len());
    for y in 0..h {
        for x in 0..w {
            let i = at(IVec2::new(x, y));
            let c = rgb(current[i]);
            let p = &primary[i];
            let pos = Vec2::new(x as f32, y as f32) + 0.5 + Vec2::from(p.motion);
            let q = pos.floor().as_ivec2();
            let inside = pos.x >= 0.0 && pos.y >= 0.0 && pos.x < w as f32 && pos.y < h as f32;
            if !history_valid || !inside || !matches(p, q) {
                out.push([c.x, c.y, c.z, 1.0]);
                continue;
            }
            let mut hc = bilinear(pos);
            let length = history[at(q)][3];
            if settings.clamp != TaaClamp::None {
                let (mut lo, mut hi, mut m1, mut m2, mut n) =
                    (c, c, Vec3::ZERO, Vec3::ZERO, 0.0f32);
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let t = IVec2::new(x + dx, y + dy);
                        if t.x < 0 || t.y < 0 || t.x >= w || t.y >= h {
                            continue;
                        }
                        let s = rgb(current[at(t)]);
                        lo = lo.min(s);
                        hi = hi.max(s);
                        m1 += s;
                        m2 += s * s;
                        n += 1.0;
                    }
                }
                match settings.clamp {
                    TaaClamp::MinMax => hc = hc.clamp(lo, hi),
                    TaaClamp::Variance { gamma } => {
                        let mean = m1 / n;
                        let var = (m2 / n - mean * mean).max(Vec3::ZERO);
                        let sigma = Vec3::new(var.x.sqrt(), var.y.sqrt(), var.z.sqrt());
                        hc = clip_to_box(mean - gamma * sigma, mean + gamma * sigma, hc);
                    }
                    TaaClamp::None => {}
                }
            }
            let a = settings.alpha.max(1.0 / (length + 1.0));
            let r = hc * (1.0 - a) + c * a;
            out.push([r.x, r.y, r.z, (length + 1.0).min(settings.max_history)]);
        }
    }
    out
}

/// Clips `h` towards the centre of the box [lo, hi].
pub fn clip_to_box(lo: Vec3, hi: Vec3, h: Vec3) -> Vec3 {
    let centre = 0.5 * (hi + lo);
    let extent = 0.5 * (hi - lo) + Vec3::splat(1.0e-6);
    let v = h - centre;
    let m = (v / extent).abs().max_element();
    if m > 1.0 { centre + v / m } else { h }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_inside_points_and_moves_outside_ones_onto_the_box() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        assert_eq!(clip_to_box(lo, hi, Vec3::splat(0.3)), Vec3::splat(0.3));
        let c = clip_to_box(lo, hi, Vec3::new(3.0, 0.5, 0.5));
        assert!((c - Vec3::new(1.0, 0.5, 0.5)).length() < 1e-5, "{c}");
    }

    #[test]
    fn a_static_pixel_averages_uniformly_then_exponentially() {
        let s = TaaSettings { clamp: TaaClamp::None, alpha: 0.1, ..Default::default() };
        let p = TaaPrimary {
            normal: [0.0, 1.0, 0.0],
            depth: 2.0,
            motion: [0.0, 0.0],
            instance: 0,
            previous_depth: 2.0,
        };
        let mut history = vec![[0.0; 4]];
        let mut prev = vec![p];
        let mut valid = false;
        let samples = [1.0f32, 3.0, 5.0];
        for (k, v) in samples.iter().enumerate() {
            history = resolve(&s, (1, 1), valid, &[[*v, *v, *v, 1.0]], &[p], &prev, &history);
            prev = vec![p];
            valid = true;
            let mean = samples[..=k].iter().sum::<f32>() / (k + 1) as f32;
            assert!((history[0][0] - mean).abs() < 1e-5, "frame {k}: {} vs {mean}", history[0][0]);
            assert_eq!(history[0][3], (k + 1) as f32);
        }
    }
}
