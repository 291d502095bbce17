//! The thesis's dynamic tests (Sec. 7.4) as synthetic irradiance sequences: a plane of one SSS
//! material seen from above, lit by point lights, with a bar casting a hard shadow edge, a
//! non-SSS strip on the left (mask 0), and per test what changes over time. The irradiance is
//! computed in closed form (cos θ / dist², hard disc and bar occluders), not path traced.

use sss::SssFrame;
use sss::sampling::pcg_hash;

/// Which of the thesis's dynamic tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicTest {
    /// I(t) = sin(2π f t) + 1, f = 5 Hz.
    Flash,
    /// The main light toggled every `period` frames, two flickering candles.
    Toggle,
    /// Six disc occluders circling like a flock, casting moving shadows.
    Boids,
}

/// Frame time step: 60 frames per second.
pub const DT: f32 = 1.0 / 60.0;
/// f of the flash test.
pub const FLASH_HZ: f32 = 5.0;
/// The toggle's half period in frames (the thesis's 3 s do not fit a 60-frame run: 0.5 s).
pub const TOGGLE_FRAMES: u32 = 30;

/// The flash's intensity at frame t.
pub fn flash_intensity(frame: u32) -> f32 {
    (2.0 * std::f32::consts::PI * FLASH_HZ * frame as f32 * DT).sin() + 1.0
}

struct Light {
    pos: [f32; 3],
    intensity: f32,
}

fn candle_flicker(candle: u32, frame: u32) -> f32 {
    0.7 + 0.6 * ((pcg_hash(frame * 2 + candle) >> 8) as f32 / 16_777_216.0)
}

/// The frame's irradiance at `width`x`height`, with d per channel given in units of the
/// image height (converted to pixels here, so the look is the same at every resolution).
pub fn frame(test: DynamicTest, width: u32, height: u32, frame: u32, d_rel: [f32; 3]) -> SssFrame {
    let aspect = width as f32 / height as f32;
    let main_on = match test {
        DynamicTest::Toggle => (frame / TOGGLE_FRAMES).is_multiple_of(2),
        _ => true,
    };
    let main = Light {
        pos: [0.35 * aspect, 0.3, 0.6],
        intensity: if test == DynamicTest::Flash {
            flash_intensity(frame)
        } else if main_on {
            1.0
        } else {
            0.0
        },
    };
    let mut lights = vec![main];
    if test == DynamicTest::Toggle {
        lights.push(Light {
            pos: [0.75 * aspect, 0.7, 0.12],
            intensity: 0.05 * candle_flicker(0, frame),
        });
        lights.push(Light {
            pos: [0.55 * aspect, 0.85, 0.1],
            intensity: 0.04 * candle_flicker(1, frame),
        });
    }
    // Boids: discs at height 0.3 on circles around (0.5 aspect, 0.5), radius 0.05.
    let t = frame as f32 * DT;
    let boids: Vec<[f32; 3]> = if test == DynamicTest::Boids {
        (0..6)
            .map(|k| {
                let phase = k as f32 * 1.047 + 2.0 * t * (1.0 + 0.1 * k as f32);
                let radius = 0.15 + 0.03 * k as f32;
                [0.5 * aspect + radius * phase.cos(), 0.5 + 0.6 * radius * phase.sin(), 0.3]
            })
            .collect()
    } else {
        vec![]
    };
    let mut irradiance = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let p = [(x as f32 + 0.5) / height as f32, (y as f32 + 0.5) / height as f32];
            let mask = if p[0] < 0.12 * aspect { 0.0 } else { 1.0 };
            let mut e = 0.0;
            for l in &lights {
                let v = [l.pos[0] - p[0], l.pos[1] - p[1], l.pos[2]];
                let dist2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                let cos = v[2] / dist2.sqrt();
                // The bar at height 0.2 over x in [0.55, 0.6] aspect: the ray from p to the light
                // passes height 0.2 at p + v · (0.2 / v_z).
                let s = 0.2 / v[2];
                let bar_x = p[0] + v[0] * s;
                let mut visible = !(0.55 * aspect..0.6 * aspect).contains(&bar_x) || s > 1.0;
                for b in &boids {
                    let s = b[2] / v[2];
                    let (qx, qy) = (p[0] + v[0] * s, p[1] + v[1] * s);
                    if s < 1.0 && (qx - b[0]).powi(2) + (qy - b[1]).powi(2) < 0.05 * 0.05 {
                        visible = false;
                    }
                }
                if visible {
                    // 0.36 = 0.6²: the main light at unit intensity gives irradiance 1 right below it.
                    e += l.intensity * cos / dist2 * 0.36;
                }
            }
            irradiance.push([e, 0.85 * e, 0.7 * e, mask]);
        }
    }
    SssFrame {
        width,
        height,
        irradiance,
        d_px: d_rel.map(|d| d * height as f32),
        focal_px: 0.0,
        motion: Vec::new(),
    }
}
