//! A frame of the cache: its four stages, each one timed submission, and its read-back.

use super::SampleCache;
use crate::gpu_types::{GpuPixel, HEADER_WORDS, RETRACE_ARGS_WORD, SHADE_ARGS_WORD, SscParams};
use crate::output::{CacheFrame, CacheStats};
use crate::passes::{PASSES, STAGE_DISPATCHES, list_dispatch};
use crate::settings::{Retrace, ShadingMode};
use crate::slope;
use render::error::RenderError;
use render::gpu::Gpu;
use render::pass_library::LibraryPipeline;
use render::scene_gpu::SceneGpu;
use render::timing::PassTiming;

impl SampleCache {
    /// Renders one frame: call after `scene.update` for this frame's scene. `frame` seeds the
    /// frame's randomness (with `seed`) and drives the round robins. The four stages of
    /// [`PASSES`] in order; the frame's systems call [`Self::stage`] one by one instead.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) -> Result<CacheFrame, RenderError> {
        self.begin_frame(seed, frame);
        for stage in 0..PASSES.len() {
            self.stage(gpu, scene, stage)?;
        }
        self.finish_frame(gpu)
    }

    /// Starts frame `frame`; then [`Self::stage`] 0 to 3, then [`Self::finish_frame`].
    pub fn begin_frame(&mut self, seed: u64, frame: u32) {
        self.pending = Some((seed, frame, Vec::new()));
    }

    /// Stage `stage` of [`PASSES`] (reserve = reprojection, trace, shade, reconstruct) as one
    /// timed submission. Each stage writes the cache's own frame parameters from the scene as
    /// it is then.
    pub fn stage(&mut self, gpu: &Gpu, scene: &SceneGpu, stage: usize) -> Result<(), RenderError> {
        let (w, h) = (self.width, self.height);
        if scene.settings().width != w || scene.settings().height != h {
            return Err(RenderError::Settings(format!(
                "sample cache is {w}x{h}, the scene {}x{}",
                scene.settings().width,
                scene.settings().height
            )));
        }
        let Some((seed, frame, _)) = self.pending else {
            return Err(RenderError::Settings("sample cache: stage before begin_frame".into()));
        };
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        let s = &self.settings;
        if stage == 0 {
            let vfov = 2.0 * tan_half_fov(scene).atan();
            let pixels = w * h;
            let params = SscParams {
                width: w,
                height: h,
                slots: s.slots,
                frame,
                retrace: match s.retrace {
                    Retrace::Single => 0,
                    Retrace::Multi => 1,
                    Retrace::Adaptive => 2,
                },
                shading: match s.shading {
                    ShadingMode::Uniform => 0,
                    ShadingMode::Adaptive => 1,
                },
                base_block: s.base_block,
                buckets: s.buckets,
                n_target: s.n_target,
                delta: s.delta,
                epsilon0: s.epsilon0,
                epsilon1: s.epsilon1,
                alpha: s.alpha,
                shading_budget: s.shading_rate * pixels as f32,
                pixel_diagonal_angle: slope::pixel_diagonal_angle(vfov, h),
                roughness_alpha: s.roughness_alpha as u32,
            };
            gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        }

        let mut timed = self.timers[stage].begin(gpu, PASSES[stage]);
        if stage == 0 {
            let encoder = timed.encoder();
            encoder.clear_buffer(&self.pixel_atomics, 0, None);
            encoder.clear_buffer(&self.reserve_keys, 0, None);
            // Header words 0-5 and 10-31; 6-9 (importance bounds) carry over, begin_main moves them.
            encoder.clear_buffer(&self.work, 0, Some(24));
            encoder.clear_buffer(&self.work, 40, Some((HEADER_WORDS - 10) * 4));
            if self.frames == 0 {
                // The very first frame reprojects an empty cache.
                encoder.clear_buffer(&self.caches[self.current].mask, 0, None);
                encoder.clear_buffer(&self.work, 0, Some(HEADER_WORDS * 4));
            }
        }
        let bind_group = &self.bind_groups[self.current];
        let (gx, gy) = (w.div_ceil(8), h.div_ceil(8));
        let p = &self.pipelines;
        // A list pass: its indirect arguments' offset in `list_args` and header word in `work`.
        let list = |l: u64| Some((12 * l, [RETRACE_ARGS_WORD, SHADE_ARGS_WORD][l as usize]));
        let whole_list = list_dispatch(s.slots * w * h);
        // In the order of DISPATCHES: pipeline, direct workgroups, list.
        let dispatches: [(&LibraryPipeline, [u32; 3], Option<(u64, u64)>); 13] = [
            (&p.begin, [1, 1, 1], None),
            (&p.reserve, [gx, gy, s.slots], None),
            (&p.gather, [gx, gy, 1], None),
            (&p.closest, [gx, gy, 1], None),
            (&p.retrace, [gx, gy, 1], None),
            (&p.retrace_args, [1, 1, 1], None),
            (&p.retrace_list, whole_list, list(0)),
            (&p.finish, [gx, gy, 1], None),
            (&p.rates, [1, 1, 1], None),
            (&p.select, [gx, gy, 1], None),
            (&p.shade_args, [1, 1, 1], None),
            (&p.shade, whole_list, list(1)),
            (&p.reconstruct, [gx, gy, 1], None),
        ];
        for (i, d) in STAGE_DISPATCHES[stage].clone().enumerate() {
            let (pipeline, [x, y, z], list) = dispatches[d];
            let indirect = list.filter(|_| self.indirect);
            if let Some((offset, word)) = indirect {
                timed.encoder().copy_buffer_to_buffer(
                    &self.work,
                    word * 4,
                    &self.list_args,
                    offset,
                    12,
                );
            }
            timed.pass(i, |pass| {
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, bind_group, &[]);
                pass.set_pipeline(&pipeline.get());
                match indirect {
                    Some((offset, _)) => pass.dispatch_workgroups_indirect(&self.list_args, offset),
                    None => pass.dispatch_workgroups(x, y, z),
                }
            })?;
        }
        if stage == PASSES.len() - 1 {
            let encoder = timed.encoder();
            self.out_readback.record(encoder, &self.out, 0);
            self.header_readback.record(encoder, &self.work, 0);
        }
        let times = timed.submit()?;
        if let Some((_, _, all)) = &mut self.pending {
            all.extend(times);
        }
        Ok(())
    }

    /// Ends the frame after its four stages: swaps the caches and reads the image and counters.
    pub fn finish_frame(&mut self, gpu: &Gpu) -> Result<CacheFrame, RenderError> {
        let Some((_, _, dispatch_timings)) = self.pending.take() else {
            return Err(RenderError::Settings(
                "sample cache: finish_frame before begin_frame".into(),
            ));
        };
        let s = &self.settings;
        let mut timings = Vec::new();
        for t in &dispatch_timings {
            let pass = t.pass.split('/').next().unwrap_or(&t.pass);
            render::timing::merge(
                &mut timings,
                vec![PassTiming { pass: pass.into(), ..t.clone() }],
            );
        }
        self.current = 1 - self.current;
        self.frames += 1;

        let out: Vec<GpuPixel> = self.out_readback.read(gpu)?;
        let header: Vec<u32> = self.header_readback.read(gpu)?;
        let stats = CacheStats {
            shaded: header[0],
            rays: header[1],
            all_rays: header[34],
            new_samples: header[2],
            purged: header[3],
            reprojected: header[4],
            dropped: header[5],
            visible: header[12],
            occupied: header[13],
            base_shaded: header[14],
            slope_flagged: header[15],
            retrace_listed: header[33],
            list_args: [0, 1].map(|l| {
                let at = [RETRACE_ARGS_WORD, SHADE_ARGS_WORD][l] as usize;
                [header[at], header[at + 1], header[at + 2]]
            }),
            importance_bounds: (f32::from_bits(header[8]), f32::from_bits(header[9])),
            histogram: header[16..16 + s.buckets as usize].to_vec(),
            threshold: header[10],
            coin: f32::from_bits(header[11]),
        };
        Ok(CacheFrame {
            radiance: out.iter().map(|p| p.radiance).collect(),
            motion: out.iter().map(|p| p.motion).collect(),
            flags: out.iter().map(|p| p.flags).collect(),
            stats,
            timings,
            dispatch_timings,
        })
    }
}

fn tan_half_fov(scene: &SceneGpu) -> f32 {
    (0.5 * scene.camera().vfov).tan()
}
