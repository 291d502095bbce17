//! The SSS pass's noise-free irradiance (Sec. 5.3.1's pre-integrated lighting B(p); the thesis
//! scatters UE4's deferred direct lighting): per pixel, the pixel-centre ray's hit lit by every
//! point, spot and directional light with an exact shadow ray, Σ E_l cos θ V / π (Lambert
//! radiance over the albedo). `DirectIrradiancePass` is the WGSL pass
//! (shaders/direct_irradiance.wgsl), `direct_irradiance` its CPU twin (brute-force rays over every
//! triangle: for tests on tiny images). No random number: the same frame gives the same image
//! whatever the seed, which is what SPVG needs to see only the lighting's temporal change.

use glam::{Mat3, Vec2, Vec3};
use render::bvh::{WatertightRay, intersect_triangle};
use render::compute::{self, BufferBinding};
use render::error::RenderError;
use render::frame::CameraBasis;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::pass_library::{LibraryPipeline, PassLibrary};
use render::scene::{Light, SceneDesc};
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};
use serde::{Deserialize, Serialize};

/// The pass name in the method's timings.
pub const DIRECT_PASS: &str = "sss_direct";

/// What the SSS pass scatters on the subsurface pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum IrradianceSource {
    /// The thesis's: direct lighting of the analytic lights with exact shadow rays (noise-free).
    #[default]
    Direct,
    /// The path tracer's radiance at `spp` samples per pixel divided by the albedo (all
    /// transport, with its Monte Carlo noise).
    PathTraced,
}

const WORKGROUP: u32 = 8;

const OWN_GROUP: [BufferBinding; 1] = [BufferBinding::read_write("direct_out", "array<vec4f>")];

/// The WGSL pass: one invocation per pixel, its own frame parameters and output.
pub struct DirectIrradiancePass {
    width: u32,
    height: u32,
    frame: FrameBindings,
    pipeline: LibraryPipeline,
    bind_group: wgpu::BindGroup,
    out: wgpu::Buffer,
    timer: PassTimer,
}

impl DirectIrradiancePass {
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self, RenderError> {
        let s = scene.settings();
        let (width, height) = (s.width, s.height);
        gpu.check_resolution(width, height, 16)?;
        let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sss direct irradiance"),
            size: width as u64 * height as u64 * 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let (layout, [pipeline]) = scene.library_pass(
            gpu,
            "direct_irradiance.wgsl",
            Self::program(),
            &OWN_GROUP,
            ["sss_direct"],
        )?;
        let bind_group = compute::buffer_group(gpu, "sss direct", &layout, &[&out]);
        Ok(Self {
            width,
            height,
            frame: FrameBindings::new(gpu, scene),
            pipeline,
            bind_group,
            out,
            timer: PassTimer::new(gpu, &[DIRECT_PASS]),
        })
    }

    /// The pass's program: the shading library, its @group(2), direct_irradiance.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let bindings: Module =
                compute::group_module("package::sss_direct_bindings", 2, &OWN_GROUP, &[]);
            PassLibrary::program([bindings], [render::wgsl_file!("direct_irradiance.wgsl")])
        })
    }

    /// The current scene's direct irradiance, row-major (w = 0), and the pass's time.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        frame: u32,
    ) -> Result<(Vec<[f32; 4]>, Vec<PassTiming>), RenderError> {
        // spp 1, seed 0: the pass draws no random number.
        self.frame.prepare(gpu, scene, 1, 0, 0, frame);
        let mut timed = self.timer.begin(gpu, "sss direct");
        timed.pass(0, |pass| {
            pass.set_pipeline(&self.pipeline.get());
            self.frame.bind(gpu, scene, pass);
            pass.set_bind_group(2, &self.bind_group, &[]);
            pass.dispatch_workgroups(
                self.width.div_ceil(WORKGROUP),
                self.height.div_ceil(WORKGROUP),
                1,
            );
        })?;
        let timings = timed.submit()?;
        let e = render::readback::read_pod(gpu, &self.out, "sss direct irradiance")?;
        Ok((e, timings))
    }
}

/// One world-space triangle with its vertex normals (None: flat).
struct WorldTriangle {
    v: [Vec3; 3],
    n: Option<[Vec3; 3]>,
}

fn world_triangles(scene: &SceneDesc) -> Vec<WorldTriangle> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh as usize];
        let m = inst.transform;
        let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
        for idx in &mesh.indices {
            let v = idx.map(|i| m.transform_point3(mesh.positions[i as usize]));
            let n = (!mesh.normals.is_empty())
                .then(|| idx.map(|i| normal_matrix * mesh.normals[i as usize]));
            out.push(WorldTriangle { v, n });
        }
    }
    out
}

/// The closest hit (triangle, t, barycentrics of vertices 1 and 2) before `t_max`.
fn closest(tris: &[WorldTriangle], o: Vec3, d: Vec3, t_max: f32) -> Option<(usize, f32, Vec2)> {
    let ray = WatertightRay::new(o, d);
    let mut best: Option<(usize, f32, Vec2)> = None;
    for (k, t) in tris.iter().enumerate() {
        let limit = best.map_or(t_max, |b| b.1);
        if let Some((th, b)) = intersect_triangle(&ray, t.v[0], t.v[1], t.v[2], limit) {
            best = Some((k, th, b));
        }
    }
    best
}

/// The CPU twin of the pass: the scene's direct irradiance / π per pixel (rgb), row-major, for
/// `width` x `height` pixels. Brute force over every triangle: tiny images and scenes only.
pub fn direct_irradiance(scene: &SceneDesc, width: u32, height: u32) -> Vec<[f32; 3]> {
    let tris = world_triangles(scene);
    let cam = CameraBasis::new(&scene.camera, width, height);
    let mut out = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let d = cam.ray_direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), width, height);
            let Some((k, t, b)) = closest(&tris, cam.position, d, 1.0e30) else {
                out.push([0.0; 3]);
                continue;
            };
            let tri = &tris[k];
            let w = Vec3::new(1.0 - b.x - b.y, b.x, b.y);
            let p = cam.position + t * d;
            let geometric = (tri.v[1] - tri.v[0]).cross(tri.v[2] - tri.v[0]).normalize_or(Vec3::Z);
            let shading = tri
                .n
                .map(|n| (w.x * n[0] + w.y * n[1] + w.z * n[2]).normalize_or(geometric))
                .unwrap_or(geometric);
            // orient(): the geometric normal towards the camera, the shading normal on its side.
            let ng = if geometric.dot(-d) >= 0.0 { geometric } else { -geometric };
            let ns = if shading.dot(ng) >= 0.0 { shading } else { -shading };
            let mut e = Vec3::ZERO;
            for light in &scene.lights {
                let (wi, dist, weight) = match *light {
                    Light::Directional { direction, irradiance, .. } => {
                        (-direction.normalize_or(Vec3::NEG_Y), 1.0e30, irradiance)
                    }
                    Light::Point { position, intensity } => {
                        let v = position - p;
                        let d2 = v.length_squared().max(1e-20);
                        (v / d2.sqrt(), d2.sqrt(), intensity / d2)
                    }
                    Light::Spot { position, direction, intensity, inner_angle, outer_angle } => {
                        let v = position - p;
                        let d2 = v.length_squared().max(1e-20);
                        let wi = v / d2.sqrt();
                        let axis = direction.normalize_or(Vec3::NEG_Y);
                        let f = spot_falloff((-wi).dot(axis), outer_angle.cos(), inner_angle.cos());
                        (wi, d2.sqrt(), intensity / d2 * f)
                    }
                };
                let cos_s = ns.dot(wi);
                if wi.dot(ng) <= 0.0 || cos_s <= 0.0 || weight.max_element() <= 0.0 {
                    continue;
                }
                let o = offset_origin(p, ng, wi);
                if closest(&tris, o, wi, dist * (1.0 - 1.0e-4)).is_some() {
                    continue;
                }
                e += weight * cos_s;
            }
            out.push((e * std::f32::consts::FRAC_1_PI).to_array());
        }
    }
    out
}

/// pt_lights.wgsl's smoothstep between the outer and inner cones.
fn spot_falloff(cos_axis: f32, cos_outer: f32, cos_inner: f32) -> f32 {
    if cos_inner <= cos_outer {
        return if cos_axis >= cos_outer { 1.0 } else { 0.0 };
    }
    let t = ((cos_axis - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// pt_scene.wgsl's offset_origin: off the surface along ng, on the side `dir` leaves to.
fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let scale = 1.0e-4 * (1.0 + p.abs().max_element());
    p + ng * if dir.dot(ng) >= 0.0 { scale } else { -scale }
}
