//! Per-dispatch constants of the path tracer (the WGSL `Frame` uniform) and the pinhole camera
//! model it uses, with the same math on the CPU for tests and motion-vector checks.

use crate::scene::Camera;
use glam::{Vec2, Vec3};

/// Orthonormal pinhole camera basis, as the shader sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    pub position: Vec3,
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub tan_half_fov: f32,
    pub aspect: f32,
}

impl CameraBasis {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.target - camera.position).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(camera.up).normalize_or(Vec3::X);
        let up = right.cross(forward);
        Self {
            position: camera.position,
            forward,
            right,
            up,
            tan_half_fov: (0.5 * camera.vfov).tan(),
            aspect: width as f32 / height as f32,
        }
    }

    /// Direction of the ray through image point `pixel` (x right, y down, pixel centres at +0.5).
    pub fn ray_direction(&self, pixel: Vec2, width: u32, height: u32) -> Vec3 {
        let ndc =
            Vec2::new(2.0 * pixel.x / width as f32 - 1.0, 1.0 - 2.0 * pixel.y / height as f32);
        (self.forward
            + ndc.x * self.tan_half_fov * self.aspect * self.right
            + ndc.y * self.tan_half_fov * self.up)
            .normalize()
    }

    /// Image point of a world position, `None` behind the camera.
    pub fn project(&self, point: Vec3, width: u32, height: u32) -> Option<Vec2> {
        let d = point - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let ndc = Vec2::new(
            d.dot(self.right) / (z * self.tan_half_fov * self.aspect),
            d.dot(self.up) / (z * self.tan_half_fov),
        );
        Some(Vec2::new((0.5 * ndc.x + 0.5) * width as f32, (0.5 - 0.5 * ndc.y) * height as f32))
    }

    fn gpu(&self) -> CameraFrame {
        CameraFrame {
            position: self.position.to_array(),
            tan_half_fov: self.tan_half_fov,
            forward: self.forward.to_array(),
            aspect: self.aspect,
            right: self.right.to_array(),
            pad0: 0.0,
            up: self.up.to_array(),
            pad1: 0.0,
        }
    }
}

crate::gpu_struct! {
    /// A pinhole camera as the shaders see it ([`CameraBasis`]).
    pub struct CameraFrame {
        pub position: [f32; 3] => "vec3f",
        pub tan_half_fov: f32 => "f32",
        pub forward: [f32; 3] => "vec3f",
        /// Width / height.
        pub aspect: f32 => "f32",
        pub right: [f32; 3] => "vec3f",
        pub pad0: f32 => "f32",
        pub up: [f32; 3] => "vec3f",
        pub pad1: f32 => "f32",
    }
}

crate::gpu_struct! {
    /// The `frame` uniform of every pass built on the shading library (@group(0) binding 0).
    pub struct Frame {
        pub camera: CameraFrame => "CameraFrame",
        pub previous_camera: CameraFrame => "CameraFrame",
        /// Constant environment radiance.
        pub environment: [f32; 3] => "vec3f",
        /// Total emitter weight W = sum of luminance(Le) * area over emissive triangles.
        pub emitter_weight: f32 => "f32",
        pub width: u32 => "u32",
        pub height: u32 => "u32",
        /// Samples per pixel of this dispatch.
        pub spp: u32 => "u32",
        /// Index of the dispatch's first sample.
        pub first_sample: u32 => "u32",
        pub seed_lo: u32 => "u32",
        pub seed_hi: u32 => "u32",
        pub frame: u32 => "u32",
        pub max_depth: u32 => "u32",
        /// Russian roulette applies from this depth on.
        pub rr_start_depth: u32 => "u32",
        pub analytic_lights: u32 => "u32",
        /// Emissive triangles in the light table.
        pub emitters: u32 => "u32",
        /// 1: add to the radiance sum, 0: replace it.
        pub accumulate: u32 => "u32",
    }
}

const _: () = assert!(size_of::<Frame>() == 192);

/// Everything that changes between dispatches.
pub(crate) struct FrameParams {
    pub camera: CameraBasis,
    pub previous_camera: CameraBasis,
    pub environment: Vec3,
    pub emitter_weight: f32,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub first_sample: u32,
    pub seed: u64,
    pub frame: u32,
    pub max_depth: u32,
    pub rr_start_depth: u32,
    pub analytic_lights: u32,
    pub emitters: u32,
    pub accumulate: bool,
}

impl FrameParams {
    pub fn gpu(&self) -> Frame {
        Frame {
            camera: self.camera.gpu(),
            previous_camera: self.previous_camera.gpu(),
            environment: self.environment.to_array(),
            emitter_weight: self.emitter_weight,
            width: self.width,
            height: self.height,
            spp: self.spp,
            first_sample: self.first_sample,
            seed_lo: self.seed as u32,
            seed_hi: (self.seed >> 32) as u32,
            frame: self.frame,
            max_depth: self.max_depth,
            rr_start_depth: self.rr_start_depth,
            analytic_lights: self.analytic_lights,
            emitters: self.emitters,
            accumulate: self.accumulate as u32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_inverts_ray_generation_and_matches_view_projection() {
        let camera = Camera {
            position: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(-0.5, 0.3, 0.0),
            up: Vec3::Y,
            vfov: 0.9,
        };
        let (w, h) = (64, 36);
        let b = CameraBasis::new(&camera, w, h);
        let clip = camera.projection(w as f32 / h as f32) * camera.view();
        for pixel in [Vec2::new(0.5, 0.5), Vec2::new(63.5, 35.5), Vec2::new(20.25, 7.75)] {
            let p = camera.position + b.ray_direction(pixel, w, h) * 4.2;
            assert!(b.project(p, w, h).unwrap().abs_diff_eq(pixel, 1e-3));
            // The same pixel through Camera::view/projection (NDC y up, image y down).
            let ndc = clip.project_point3(p);
            let from_matrices =
                Vec2::new((ndc.x + 1.0) * 0.5 * w as f32, (1.0 - ndc.y) * 0.5 * h as f32);
            assert!(from_matrices.abs_diff_eq(pixel, 1e-3), "{from_matrices} vs {pixel}");
        }
        assert!(b.project(camera.position - b.forward, w, h).is_none());
    }
}
