//! A frame of the cache: its parameters and the update before the image and the store after.

use super::gpu_types::TcParams;
use super::passes::{INSERT_HEADER, TcPass};
use super::statistics::{COUNTERS, CacheStatistics};
use super::{TerminationCache, TerminationOutput};
use crate::gpu_decision::rule_words;
use crate::rule::TerminationRule;
use crate::settings::{Incomplete, RadianceScale, TerminationSettings};
use hash_cache::{HashCacheParams, HashCacheSettings};
use render::error::RenderError;
use render::gpu::Gpu;
use render::scene::Camera;
use render::scene_gpu::SceneGpu;
use render::timing::PassTiming;

/// During the warm-up a record averages only its last few estimates: the propagation is an
/// iteration from an empty cache, and its early, darker values must not linger.
const WARMUP_MAX_VERTICES: u32 = 4;

impl TerminationCache {
    /// One whole frame: [`Self::update`], [`Self::trace`], [`Self::store`]; the output holds
    /// the four passes' times and the store's count.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
    ) -> Result<TerminationOutput, RenderError> {
        let updated = self.update(gpu, scene, camera, seed, frame)?;
        let mut out = self.trace(gpu, scene, updated)?;
        out.timings.extend(self.store(gpu, scene)?);
        let counted = self.read_counters(gpu)?;
        out.stats.stored = counted.stored;
        out.stats.inserted = counted.inserted;
        out.stats.insert_failures = counted.insert_failures;
        Ok(out)
    }

    /// The records the image reads: on the first call the cache is first filled for
    /// `warmup_frames` whole frames (traced by the cache's own tracer), then this frame's
    /// propagation and fold (one submission). Returns their times, for [`Self::trace`].
    pub fn update(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
    ) -> Result<Vec<PassTiming>, RenderError> {
        if self.frames == 0 {
            for k in 0..self.settings.warmup_frames {
                // Warm-up frames draw their own random numbers (frame indices no run reaches).
                let frame = 0x8000_0000 + k;
                self.begin_frame(gpu, scene, camera, seed, frame, WARMUP_MAX_VERTICES);
                self.submit(gpu, scene, &self.update_timer, &TcPass::UPDATE, &self.own.group)?;
                self.submit(gpu, scene, &self.own.timer, &[TcPass::Trace], &self.own.group)?;
                self.store(gpu, scene)?;
            }
        }
        self.begin_frame(gpu, scene, camera, seed, frame, self.settings.max_vertices);
        let timings =
            self.submit(gpu, scene, &self.update_timer, &TcPass::UPDATE, &self.own.group)?;
        if self.derived_unit.is_none() {
            // The scene's radiance scale, from the records the first image reads: fixed for
            // the run, so that a static scene's frames stay independent estimates.
            self.derived_unit = Some(CacheStatistics::of(&self.read_records(gpu)?).mean);
        }
        Ok(timings)
    }

    /// The radiance unit of an absolute threshold for `settings` (`radiance_scale`): the
    /// stated one, or the cache's mean once derived (before that, during the warm-up, 1).
    pub fn radiance_unit(&self, settings: &TerminationSettings) -> f64 {
        match settings.radiance_scale {
            RadianceScale::Stated => settings.radiance_unit,
            RadianceScale::CacheMean => self.derived_unit.unwrap_or(1.0),
        }
    }

    /// After the frame's image: the frame's new keys get slots and the winning candidates become
    /// stored vertices, which the next frame propagates. Reads only the cache's own buffers and
    /// parameters (no ray), so other methods' work since [`Self::trace`] changes nothing. Ends
    /// the frame.
    pub fn store(&mut self, gpu: &Gpu, scene: &SceneGpu) -> Result<Vec<PassTiming>, RenderError> {
        let timings =
            self.submit(gpu, scene, &self.store_timer, &TcPass::STORE, &self.own.group)?;
        self.frames += 1;
        Ok(timings)
    }

    /// The parameters of a pass with `settings`' rule in the frame of `frame` (its candidate
    /// mask and record memory).
    pub(super) fn params(
        &self,
        settings: &TerminationSettings,
        frame: TcParams,
        offers: bool,
    ) -> TcParams {
        let (rule_kind, relative, param, margin, bias_clamp) = rule_words(&settings.rule);
        let param = match settings.rule {
            TerminationRule::VarianceBounding { t, relative: false } => {
                let unit = self.radiance_unit(settings);
                (t * unit * unit) as f32
            }
            _ => param,
        };
        TcParams {
            rule_kind,
            relative,
            param,
            margin,
            bias_clamp,
            survival: settings.survival as f32,
            offers: offers as u32,
            ..frame
        }
    }

    /// Writes the frame's parameters (the cache's frame, `hc`, the own tracer's `tc`) and
    /// clears the counters.
    pub(super) fn begin_frame(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
        max_vertices: u32,
    ) {
        let s = &self.settings;
        // The hash cache's keys round the voxel down to a power of two (sub-pixel voxels, the
        // paper's HashCache); twice the scale keeps this cache's rounding up (voxels of at least
        // lod_scale footprints), as it was tuned.
        let keys = HashCacheSettings {
            capacity: s.capacity,
            probe_limit: s.probe_limit,
            lod_scale: 2.0 * s.lod_scale,
            jitter: s.jitter,
            ..Default::default()
        }
        .key_params(camera, self.height);
        let hc = HashCacheParams {
            capacity: s.capacity,
            probe_limit: s.probe_limit,
            frame: 0,
            max_age: 0,
            pixel_angle: keys.pixel_angle,
            lod_scale: keys.lod_scale,
            normal_lod: keys.normal_lod as u32,
            jitter: keys.jitter as u32,
            lookup: 0,
            max_samples: 0.0,
            voxel_jitter_seed: 0,
            pad: 0,
            primary_jitter: [0.0; 2],
            pad2: [0.0; 2],
        };
        let frame_params = TcParams {
            samples_per_vertex: s.samples_per_vertex,
            max_vertices: max_vertices.min(s.max_vertices) as f32,
            store_probability: s.store_probability as f32,
            pixels: self.width * self.height,
            candidate_mask: scene::mix64(seed ^ ((frame as u64) << 32)) as u32 & 0x0fff_ffff,
            incomplete: match s.incomplete {
                Incomplete::LeaveOut => 0,
                Incomplete::PathTrace => 1,
                Incomplete::Include => 2,
            },
            ..bytemuck::Zeroable::zeroed()
        };
        self.frame_params = frame_params;
        let tc = self.params(&self.settings, frame_params, self.own.offers);
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        gpu.queue.write_buffer(&self.hc, 0, bytemuck::bytes_of(&hc));
        gpu.queue.write_buffer(&self.own.tc, 0, bytemuck::bytes_of(&tc));
        gpu.queue.write_buffer(&self.own.counters, 0, &[0u8; COUNTERS as usize * 4]);
        gpu.queue.write_buffer(&self.inserts, 0, bytemuck::cast_slice(&INSERT_HEADER));
    }
}
