//! The screen-space SSS pass in WGSL (shaders/sss_pass.wgsl, entry `sss_scatter`): the
//! same per-pixel step as `screen_pass::pixel_step`, one invocation per pixel, with ping-pong
//! histories on the GPU; the separable variant runs shaders/separable.wgsl's two 1-D passes
//! instead. Timed per pass (`sss_scatter`, `sss_separable_h`, `sss_separable_v`) by `PassTimer`.

use super::control_variates::EmCovariance;
use super::frame_input::SssFrame;
use super::pixel::{PixelHistory, PixelResult};
use super::prefilter;
use super::screen_pass::{SssPassSettings, SssVariant};
use super::separable;
use super::spvg::SpvgHistory;
use render::error::RenderError;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::readback::read_pod;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};

/// The largest count one invocation may take (a bounded per-invocation loop; the 2048-spp
/// reference of the thesis fits).
pub const MAX_COUNT: u32 = 4096;

render::gpu_struct! {
    /// The pass's parameters: image size, frame and seed, the variant (0 fixed, 1 AS, 2 OCV,
    /// 3 CCV, 4 separable), SPVG's and the control variates' parameters, the separable
    /// kernel's tap count, AFIS's level count (0: no prefiltering) and eq. 5.12's a, the
    /// direct/distant split (on, γ or −1 for Burley's, ε_u), the focal length in pixels (eq.
    /// 7.1's depth), the monitored luminance's gamma, the reprojection's depth tolerance, the
    /// hybrid pass (on, and the sampled d from which a tile takes AFIS), d per
    /// channel in pixels (w: the sampled d), and per MIP level (offset in the chain's buffer,
    /// width, height, 0), computed once here rather than per fetch in the shader.
    pub struct SssParams {
        pub width: u32 => "u32",
        pub height: u32 => "u32",
        pub frame: u32 => "u32",
        pub seed: u32 => "u32",
        pub variant: u32 => "u32",
        pub fixed_count: u32 => "u32",
        pub n_min: u32 => "u32",
        pub n_max: u32 => "u32",
        pub alpha0: f32 => "f32",
        pub kappa: f32 => "f32",
        pub sigma0_sq: f32 => "f32",
        pub eps_a: f32 => "f32",
        pub a0: f32 => "f32",
        pub a_cv: f32 => "f32",
        pub fast_inverse: u32 => "u32",
        pub taps: u32 => "u32",
        pub mip_levels: u32 => "u32",
        pub mip_a: f32 => "f32",
        pub split: u32 => "u32",
        pub gamma: f32 => "f32",
        pub eps_u: f32 => "f32",
        pub focal_px: f32 => "f32",
        pub monitor_gamma: f32 => "f32",
        pub depth_tolerance: f32 => "f32",
        pub hybrid: u32 => "u32",
        pub hybrid_min_d: f32 => "f32",
        /// 1: eq. 5.20's m = n̂·γ; 0: Algorithm 3 (m estimated directly).
        pub gamma_scaled: u32 => "u32",
        pub pad: u32 => "u32",
        pub d_px: [f32; 4] => "vec4f",
        pub mip: [[u32; 4]; 8] => "array<vec4u, 8>",
    }
}
const _: () = assert!(std::mem::size_of::<SssParams>() == 256);
// The WGSL array length above is the chain's level bound.
const _: () = assert!(prefilter::MAX_LEVELS == 8);

/// The pass's WGSL program: the Monte Carlo pass and the separable baseline's two passes.
pub fn program() -> Program {
    let types = Module::generated("package::sss_types", &[SssParams::WGSL]);
    Program::new(vec![
        types,
        render::pass_library::PassLibrary::module("package::kernel"),
        render::pass_library::PassLibrary::module("package::pt_sampling"),
        render::wgsl_file!("sampling.wgsl"),
        render::wgsl_file!("spvg.wgsl"),
        render::wgsl_file!("mip.wgsl"),
    ])
    .entry(render::wgsl_file!("sss_pass.wgsl"))
    .entry(render::wgsl_file!("separable.wgsl"))
    .entry(render::wgsl_file!("prefilter.wgsl"))
    .entry(render::wgsl_file!("hybrid.wgsl"))
    .entry(render::wgsl_file!("hybrid_copy.wgsl"))
}

/// The passes' names in `PassTimer`, by the index `dispatch` books them under.
const PASSES: [&str; 6] = [
    "sss_scatter",
    "sss_separable_h",
    "sss_separable_v",
    "sss_prefilter",
    "sss_hybrid_setup",
    "sss_hybrid_copy",
];

/// The pass for one image size, with its buffers and two history sets (read one, write the other).
pub struct SssPass {
    width: u32,
    height: u32,
    pipeline: wgpu::ComputePipeline,
    /// The separable baseline's horizontal and vertical passes, and their bind groups.
    separable: [(wgpu::ComputePipeline, wgpu::BindGroup); 2],
    /// The hybrid pass (Sec. 5.3.2): its setup (each tile's technique into `tiles`) and P4 (the
    /// AFIS tiles' copy from buffer one, the separable intermediate, to `scattered`), and P1's
    /// bind groups per history set, `sss_scatter` writing buffer one.
    hybrid_setup: (wgpu::ComputePipeline, wgpu::BindGroup),
    hybrid_copy: (wgpu::ComputePipeline, wgpu::BindGroup),
    hybrid_groups: [wgpu::BindGroup; 2],
    tiles: wgpu::Buffer,
    kernel: wgpu::Buffer,
    /// The separable kernel last uploaded: (taps, d_px).
    kernel_for: Option<(u32, [f32; 3])>,
    params: wgpu::Buffer,
    irradiance: wgpu::Buffer,
    history: [wgpu::Buffer; 2],
    cv: [wgpu::Buffer; 2],
    scattered: wgpu::Buffer,
    /// Per pixel motion (vec2f, previous minus current position): where the histories are read.
    motion: wgpu::Buffer,
    groups: [wgpu::BindGroup; 2],
    /// AFIS's MIP chain (`prefilter::MAX_LEVELS` levels' room) and the prefiltering pass, one
    /// bind group per level (each with its level's number).
    mips: wgpu::Buffer,
    prefilter: (wgpu::ComputePipeline, Vec<wgpu::BindGroup>),
    /// Which history set holds the latest history.
    current: usize,
    timer: PassTimer,
}

fn storage(gpu: &Gpu, label: &str, size: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl SssPass {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self, RenderError> {
        if width == 0 || height == 0 {
            return Err(RenderError::Settings(format!(
                "SSS pass size {width}x{height} must be non-zero"
            )));
        }
        let [pipeline, horizontal, vertical, prefilter_pipeline, setup_pipeline, copy_pipeline] =
            render::compute::pipelines_auto_layout(gpu, "sss_scatter", &program(), PASSES)?;
        let size = width as u64 * height as u64 * 16;
        let params = gpu.buffer_init(
            "sss params",
            bytemuck::bytes_of(&<SssParams as bytemuck::Zeroable>::zeroed()),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let irradiance = storage(gpu, "sss irradiance", size);
        let history = [storage(gpu, "sss history 0", size), storage(gpu, "sss history 1", size)];
        let cv = [storage(gpu, "sss cv 0", size), storage(gpu, "sss cv 1", size)];
        let scattered = storage(gpu, "sss scattered", size);
        let motion = storage(gpu, "sss motion", width as u64 * height as u64 * 8);
        let mips = storage(
            gpu,
            "sss mips",
            prefilter::level_offset(width, height, prefilter::MAX_LEVELS) * 16,
        );
        let tiles = storage(
            gpu,
            "sss hybrid tiles",
            (width.div_ceil(crate::hybrid::TILE) * height.div_ceil(crate::hybrid::TILE)) as u64 * 4,
        );
        let intermediate = storage(gpu, "sss separable intermediate", size);
        let layout = pipeline.get_bind_group_layout(0);
        // `out`: where sss_scatter writes its result (`scattered`, or buffer one under the hybrid).
        let group = |k: usize, out: &wgpu::Buffer| {
            let buffers = [
                &params,
                &irradiance,
                &history[k],
                &cv[k],
                out,
                &history[1 - k],
                &cv[1 - k],
                &mips,
                &motion,
                &tiles,
            ];
            let entries: Vec<_> = buffers
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: b.as_entire_binding(),
                })
                .collect();
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sss pass"),
                layout: &layout,
                entries: &entries,
            })
        };
        let groups = [group(0, &scattered), group(1, &scattered)];
        let hybrid_groups = [group(0, &intermediate), group(1, &intermediate)];
        let kernel = storage(gpu, "sss separable kernel", separable::MAX_TAPS as u64 * 16);
        // Auto layouts hold only what each entry uses: the horizontal pass never sees `scattered`.
        let bound_group = |pipeline: &wgpu::ComputePipeline, buffers: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<_> = buffers
                .iter()
                .map(|&(binding, b)| wgpu::BindGroupEntry {
                    binding,
                    resource: b.as_entire_binding(),
                })
                .collect();
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sss separable"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let separable_group = |pipeline: &wgpu::ComputePipeline, buffers: &[&wgpu::Buffer]| {
            let numbered: Vec<_> =
                buffers.iter().enumerate().map(|(i, &b)| (i as u32, b)).collect();
            bound_group(pipeline, &numbered)
        };
        let h_group = bound_group(
            &horizontal,
            &[(0, &params), (1, &irradiance), (2, &kernel), (3, &intermediate), (5, &tiles)],
        );
        let v_group = separable_group(
            &vertical,
            &[&params, &irradiance, &kernel, &intermediate, &scattered, &tiles],
        );
        let setup_group = separable_group(&setup_pipeline, &[&params, &irradiance, &tiles]);
        let copy_group =
            separable_group(&copy_pipeline, &[&params, &intermediate, &scattered, &tiles]);
        let separable = [(horizontal, h_group), (vertical, v_group)];
        let level_groups = (0..prefilter::MAX_LEVELS)
            .map(|k| {
                let level = gpu.buffer_init(
                    "sss mip level",
                    bytemuck::cast_slice(&[k, 0, 0, 0]),
                    wgpu::BufferUsages::STORAGE,
                );
                separable_group(&prefilter_pipeline, &[&params, &irradiance, &mips, &level])
            })
            .collect();
        let timer = PassTimer::new(gpu, &PASSES);
        Ok(Self {
            width,
            height,
            pipeline,
            separable,
            hybrid_setup: (setup_pipeline, setup_group),
            hybrid_copy: (copy_pipeline, copy_group),
            hybrid_groups,
            tiles,
            kernel,
            kernel_for: None,
            params,
            irradiance,
            history,
            cv,
            scattered,
            motion,
            groups,
            mips,
            prefilter: (prefilter_pipeline, level_groups),
            current: 0,
            timer,
        })
    }

    /// Replaces the latest history (empty = cold start everywhere).
    pub fn set_history(&mut self, gpu: &Gpu, history: &[PixelHistory]) {
        let n = (self.width * self.height) as usize;
        let (h, c): (Vec<[f32; 4]>, Vec<[f32; 4]>) = (0..n)
            .map(|i| {
                let p = history.get(i).copied().unwrap_or_default();
                let s = p.spvg;
                (
                    // w > 0.5 marks a valid history; 1 + w carries the depth it was written at.
                    [s.mu, s.sigma2, s.nbar, if s.valid { 1.0 + p.w } else { 0.0 }],
                    [p.cv.mean_f, p.cv.mean_g, p.cv.cov_fg, p.cv.var_g],
                )
            })
            .unzip();
        gpu.queue.write_buffer(&self.history[self.current], 0, bytemuck::cast_slice(&h));
        gpu.queue.write_buffer(&self.cv[self.current], 0, bytemuck::cast_slice(&c));
    }

    /// One frame: uploads the irradiance, runs `sss_scatter`, flips the histories.
    pub fn dispatch(
        &mut self,
        gpu: &Gpu,
        frame: &SssFrame,
        settings: &SssPassSettings,
        frame_index: u32,
    ) -> Result<Vec<PassTiming>, RenderError> {
        if (frame.width, frame.height) != (self.width, self.height)
            || frame.irradiance.len() != (self.width * self.height) as usize
        {
            return Err(RenderError::Settings(format!(
                "SSS frame {}x{} ({} texels) does not match the pass's {}x{}",
                frame.width,
                frame.height,
                frame.irradiance.len(),
                self.width,
                self.height
            )));
        }
        settings.validate().map_err(|e| RenderError::Settings(format!("SSS {e}")))?;
        let mip_levels =
            settings.mip_levels().map_err(|e| RenderError::Settings(format!("SSS {e}")))?;
        let (fixed, taps) = match settings.variant {
            SssVariant::Fixed { count } => (count, 0),
            SssVariant::Separable { taps } => (0, taps),
            _ => (0, 0),
        };
        // The hybrid's separable tiles take its own taps; its AFIS tiles the variant's count.
        let taps = settings.hybrid.map_or(taps, |h| h.taps);
        let hybrid = settings.hybrid.is_some();
        if taps > 0 && self.kernel_for != Some((taps, frame.d_px)) {
            let kernel = separable::kernel(taps, frame.d_px).map_err(RenderError::Settings)?;
            gpu.queue.write_buffer(&self.kernel, 0, bytemuck::cast_slice(&kernel));
            self.kernel_for = Some((taps, frame.d_px));
        }
        let most = fixed.max(settings.spvg.n_max);
        if most == 0 || most > MAX_COUNT {
            return Err(RenderError::Settings(format!(
                "SSS sample count {most} must be in [1, {MAX_COUNT}]"
            )));
        }
        gpu.check_loop_iterations("sss_scatter", most as u64)?;
        let s = &settings.spvg;
        let p = SssParams {
            width: self.width,
            height: self.height,
            frame: frame_index,
            seed: settings.seed,
            variant: settings.variant.code(),
            fixed_count: fixed,
            n_min: s.n_min,
            n_max: s.n_max,
            alpha0: s.alpha0,
            kappa: s.kappa,
            sigma0_sq: s.sigma0_sq,
            eps_a: settings.eps_a,
            a0: settings.a0,
            a_cv: settings.a_cv,
            fast_inverse: settings.fast_inverse as u32,
            taps,
            mip_levels,
            mip_a: settings.prefilter.map_or(0.0, |p| p.a),
            split: settings.split.is_some() as u32,
            // Negative: Table 5.1's Burley γ = 1 − cdf(r0) per channel.
            gamma: settings.split.and_then(|s| s.gamma).unwrap_or(-1.0),
            eps_u: settings.split.map_or(0.0, |s| s.eps_u),
            focal_px: frame.focal_px,
            monitor_gamma: settings.monitor_gamma,
            depth_tolerance: settings.depth_tolerance,
            hybrid: hybrid as u32,
            hybrid_min_d: settings.hybrid.map_or(0.0, |h| h.min_d_px()),
            gamma_scaled: (settings.distant_count == crate::DistantCount::GammaScaled) as u32,
            pad: 0,
            d_px: [frame.d_px[0], frame.d_px[1], frame.d_px[2], frame.d_sample()],
            mip: std::array::from_fn(|k| {
                let (w, h) = prefilter::level_size(self.width, self.height, k as u32);
                [prefilter::level_offset(self.width, self.height, k as u32) as u32, w, h, 0]
            }),
        };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        gpu.queue.write_buffer(&self.irradiance, 0, bytemuck::cast_slice(&frame.irradiance));
        let n = (self.width * self.height) as usize;
        let still;
        let motion: &[[f32; 2]] = if frame.motion.len() == n {
            &frame.motion
        } else if frame.motion.is_empty() {
            still = vec![[0.0f32; 2]; n];
            &still
        } else {
            return Err(RenderError::Settings(format!(
                "SSS motion has {} texels; expected {n} or none",
                frame.motion.len()
            )));
        };
        gpu.queue.write_buffer(&self.motion, 0, bytemuck::cast_slice(motion));
        let mut timed = self.timer.begin(gpu, "sss frame");
        let (gx, gy) = (self.width.div_ceil(8), self.height.div_ceil(8));
        if hybrid {
            let (pipeline, group) = &self.hybrid_setup;
            timed.pass(4, |pass| {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                // One invocation per tile.
                pass.dispatch_workgroups(gx.div_ceil(8), gy.div_ceil(8), 1);
            })?;
        }
        if mip_levels > 0 {
            let (pipeline, groups) = &self.prefilter;
            timed.pass(3, |pass| {
                pass.set_pipeline(pipeline);
                // One dispatch per level, each reading the last (wgpu orders them).
                for (k, group) in groups.iter().enumerate().take(mip_levels as usize) {
                    let (w, h) = prefilter::level_size(self.width, self.height, k as u32);
                    pass.set_bind_group(0, group, &[]);
                    pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
                }
            })?;
        }
        // The order of Sec. 5.3.2 under the hybrid: setup, prefilter, P1 (`sss_scatter` into
        // buffer one), P2 and P3 (the separable passes), P4 (the copy); wgpu orders the passes.
        let full = (gx, gy);
        let mut passes: Vec<(usize, &wgpu::ComputePipeline, &wgpu::BindGroup)> = Vec::new();
        if hybrid {
            passes.push((0, &self.pipeline, &self.hybrid_groups[self.current]));
        }
        if taps > 0 {
            passes.extend(self.separable.iter().enumerate().map(|(k, (p, g))| (1 + k, p, g)));
        } else {
            passes.push((0, &self.pipeline, &self.groups[self.current]));
        }
        if hybrid {
            passes.push((5, &self.hybrid_copy.0, &self.hybrid_copy.1));
        }
        for (index, pipeline, group) in passes {
            timed.pass(index, |pass| {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(full.0, full.1, 1);
            })?;
        }
        let times = timed.submit()?;
        // The separable passes keep no history: the Monte Carlo histories stay as they were.
        if taps == 0 || hybrid {
            self.current = 1 - self.current;
        }
        Ok(times)
    }

    fn read(
        &self,
        gpu: &Gpu,
        buffer: &wgpu::Buffer,
        what: &str,
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        let mut all: Vec<[f32; 4]> = read_pod(gpu, buffer, what)?;
        all.truncate((self.width * self.height) as usize);
        Ok(all)
    }

    /// The last frame's MIP chain, `levels` levels (rgb, share of SSS texels per texel).
    pub fn mips(&self, gpu: &Gpu, levels: u32) -> Result<Vec<Vec<[f32; 4]>>, RenderError> {
        let all: Vec<[f32; 4]> = read_pod(gpu, &self.mips, "sss mips")?;
        Ok((0..levels.min(prefilter::MAX_LEVELS))
            .map(|k| {
                let start = prefilter::level_offset(self.width, self.height, k) as usize;
                let (w, h) = prefilter::level_size(self.width, self.height, k);
                all[start..start + (w * h) as usize].to_vec()
            })
            .collect())
    }

    /// The hybrid's last technique per tile (row-major ⌈w/8⌉ x ⌈h/8⌉; `hybrid::Technique` codes).
    pub fn tiles(&self, gpu: &Gpu) -> Result<Vec<u32>, RenderError> {
        let mut all: Vec<u32> = read_pod(gpu, &self.tiles, "sss hybrid tiles")?;
        let t = crate::hybrid::TILE;
        all.truncate((self.width.div_ceil(t) * self.height.div_ceil(t)) as usize);
        Ok(all)
    }

    /// The last frame's results (scattered rgb, count).
    pub fn results(&self, gpu: &Gpu) -> Result<Vec<PixelResult>, RenderError> {
        Ok(self
            .read(gpu, &self.scattered, "sss scattered")?
            .into_iter()
            .map(|v| PixelResult { rgb: [v[0], v[1], v[2]], count: v[3] as u32 })
            .collect())
    }

    /// The latest histories.
    pub fn history(&self, gpu: &Gpu) -> Result<Vec<PixelHistory>, RenderError> {
        let h = self.read(gpu, &self.history[self.current], "sss history")?;
        let c = self.read(gpu, &self.cv[self.current], "sss cv history")?;
        Ok(h.into_iter()
            .zip(c)
            .map(|(h, c)| PixelHistory {
                spvg: SpvgHistory { mu: h[0], sigma2: h[1], nbar: h[2], valid: h[3] > 0.5 },
                cv: EmCovariance { mean_f: c[0], mean_g: c[1], cov_fg: c[2], var_g: c[3] },
                w: if h[3] > 0.5 { h[3] - 1.0 } else { 0.0 },
            })
            .collect())
    }
}
