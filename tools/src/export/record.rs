//! One frame's JSON record: the camera (position, target, up, field of view, view and projection
//! matrices), the jitter, every light's state and the frame's events.

use glam::Mat4;
use scene::{Light, SceneDesc};
use serde_json::{Value, json};

fn cols(m: Mat4) -> Vec<f32> {
    m.to_cols_array().to_vec()
}

fn light(l: &Light) -> Value {
    match *l {
        Light::Directional { direction, irradiance, angular_radius } => json!({
            "type": "directional", "direction": direction.to_array(),
            "irradiance": irradiance.to_array(), "angular_radius": angular_radius,
        }),
        Light::Point { position, intensity } => json!({
            "type": "point", "position": position.to_array(), "intensity": intensity.to_array(),
        }),
        Light::Spot { position, direction, intensity, inner_angle, outer_angle } => json!({
            "type": "spot", "position": position.to_array(), "direction": direction.to_array(),
            "intensity": intensity.to_array(), "inner_angle": inner_angle, "outer_angle": outer_angle,
        }),
    }
}

/// The record of frame `k` (scene `s`; `first` holds the materials' names of frame 0).
pub fn frame(
    k: u32,
    time_step: f32,
    _first: &SceneDesc,
    s: &SceneDesc,
    (w, h): (u32, u32),
    events: &[&str],
) -> Value {
    let c = &s.camera;
    json!({
        "frame": k,
        "time": k as f32 * time_step,
        "camera": {
            "position": c.position.to_array(),
            "target": c.target.to_array(),
            "up": c.up.to_array(),
            "vfov": c.vfov,
            "aspect": w as f32 / h as f32,
            // Column-major, as glTF and glam store matrices.
            "view": cols(c.view()),
            "projection": cols(c.projection(w as f32 / h as f32)),
        },
        // Pixels, x right, y down: the offset of the projection's centre. The references and
        // inputs spread their samples over each pixel and use none.
        "jitter": [0.0, 0.0],
        "lights": s.lights.iter().map(light).collect::<Vec<_>>(),
        "environment": s.environment.to_array(),
        "events": events,
    })
}
