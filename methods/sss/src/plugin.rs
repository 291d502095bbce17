//! Screen-space subsurface scattering (the `sss` crate, realtime-sss-thesis.txt): the path
//! tracer's image, demodulated by the G-buffer albedo on the pixels of each subsurface material
//! (up to 8, each with its own profile and pass), is scattered by the thesis's pass (Burley sampling with SPVG counts and control
//! variates, or a fixed count, or the separable baseline, or the hybrid of AFIS and separable)
//! and modulated back; with `taa` set,
//! taa's resolve runs over the result, as the thesis's TAA after the pass.
//! `Sss(variant: OnlineCv, taa: (alpha: 0.1))`.

use std::time::Instant;

use crate::direct::{DirectIrradiancePass, IrradianceSource};
use crate::gpu::SssPass;
use crate::profile::scaling_from_dmfp;
use crate::{
    DistantCount, Hybrid, Prefilter, Split, SpvgSettings, SssFrame, SssPassSettings, SssVariant,
};
use anyhow::{Result, bail};
use bevy_ecs::prelude::*;
use glam::Vec3;
use render::path_tracer::{NO_HIT, PathTracer};
use serde::{Deserialize, Serialize};
use taa::{Taa, TaaPrimary, TaaSettings};

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodImage, MethodOutput, MethodPlugin};

/// `Sss(variant: Adaptive, spp: 1)`; the thesis's parameters by default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SssSettings {
    /// Adaptive (AS), OnlineCv (AS+OCV), ConstantCv (AS+CCV), Fixed(count: N) or
    /// Separable(taps: N) (Jimenez et al.'s two 1-D passes, N odd).
    pub variant: SssVariant,
    /// What the pass scatters: `Direct` (the thesis's deferred direct lighting, exact shadow
    /// rays, no noise) or `PathTraced` (the path tracer's radiance over the albedo).
    pub irradiance: IrradianceSource,
    /// Path-traced samples per pixel of the image (and of the irradiance under `PathTraced`).
    pub spp: u32,
    /// Radii from g(ξ) (eq. 5.6) rather than the analytic inverse.
    pub fast_inverse: bool,
    pub spvg: SpvgSettings,
    pub eps_a: f32,
    pub a0: f32,
    pub a_cv: f32,
    /// TAA after the pass (Sec. 4.3/4.5.1: the pass feeds the engine's TAA): taa's
    /// resolve over the modulated image, its history rejected by the G-buffer's instance,
    /// depth and normal. None: no TAA.
    pub taa: Option<TaaSettings>,
    /// AFIS (Sec. 5.2): samples read a prefiltered MIP chain of the irradiance at eq. 5.12's
    /// level, `prefilter: (a: 0.0625, levels: 6)` (the thesis's a; `()` takes both defaults).
    /// None: samples read the irradiance itself. Not with Separable.
    pub prefilter: Option<Prefilter>,
    /// The direct/distant split (Sec. 5.3.1), `split: (gamma: None, eps_u: 0.01)` by default
    /// (Table 5.1's Burley γ = 1 − cdf(r0), Sec. 7.4's ε_u); `split: None` samples the whole disc.
    pub split: Option<Split>,
    /// The monitored luminance's encoding Y^(1/γ_m) (Sec. 4.4's gamma-corrected luminance; 1:
    /// linear).
    pub monitor_gamma: f32,
    /// The hybrid pass (Sec. 5.3.2), `hybrid: (taps: 25, max_gap_px: 1.0)`: AFIS (the variant
    /// on the prefiltered chain; needs `prefilter`) on the 8x8 tiles where the separable taps
    /// would lie more than max_gap_px apart, the separable passes elsewhere. None: the variant.
    pub hybrid: Option<Hybrid>,
    /// Algorithm 3's distant count (SPVG estimates m) or eq. 5.20's m = n̂·γ.
    pub distant_count: DistantCount,
}

impl Default for SssSettings {
    fn default() -> Self {
        let s = SssPassSettings::default();
        Self {
            variant: s.variant,
            irradiance: IrradianceSource::Direct,
            spp: 1,
            fast_inverse: s.fast_inverse,
            spvg: s.spvg,
            eps_a: s.eps_a,
            a0: s.a0,
            a_cv: s.a_cv,
            taa: None,
            prefilter: None,
            split: s.split,
            monitor_gamma: s.monitor_gamma,
            hybrid: s.hybrid,
            distant_count: s.distant_count,
        }
    }
}

impl SssSettings {
    pub fn label(&self) -> String {
        let base: String = match self.variant {
            SssVariant::Fixed { count } => format!("sss_fixed{count}"),
            SssVariant::Adaptive => "sss_as".into(),
            SssVariant::OnlineCv => "sss_ocv".into(),
            SssVariant::ConstantCv => "sss_ccv".into(),
            SssVariant::Separable { taps } => format!("sss_separable{taps}"),
        };
        let base = if self.prefilter.is_some() { format!("{base}_afis") } else { base };
        let base = match self.hybrid {
            Some(h) => format!("{base}_hybrid{}", h.taps),
            None => base,
        };
        let base = if self.irradiance == IrradianceSource::PathTraced {
            format!("{base}_pt")
        } else {
            base
        };
        let base = if self.distant_count == DistantCount::GammaScaled {
            format!("{base}_eq520")
        } else {
            base
        };
        if self.taa.is_some() { format!("{base}_taa") } else { base }
    }

    fn pass_settings(&self, seed: u64) -> SssPassSettings {
        SssPassSettings {
            variant: self.variant,
            spvg: self.spvg,
            fast_inverse: self.fast_inverse,
            eps_a: self.eps_a,
            a0: self.a0,
            a_cv: self.a_cv,
            seed: seed as u32,
            prefilter: self.prefilter,
            split: self.split,
            monitor_gamma: self.monitor_gamma,
            hybrid: self.hybrid,
            distant_count: self.distant_count,
            ..Default::default()
        }
    }
}

/// The most subsurface materials one image scatters (a pass each).
pub const MAX_SSS_MATERIALS: usize = 8;

/// One subsurface material's profile and its pass. Each material's pixels are scattered by their
/// own pass, in which the other materials' pixels are off the mask: a profile reads only its own
/// material's irradiance (no bleeding between materials, as none from other surfaces).
pub struct SssProfile {
    /// The material's index in `SceneDesc::materials`.
    material: u32,
    /// Burley's d per channel in scene units (Θ3 of eq. 2.44 from dmfp and the base colour).
    d: [f32; 3],
    pass: SssPass,
}

#[derive(Component)]
pub struct SssState {
    settings: SssSettings,
    /// The path tracer whose image and G-buffer the passes scatter.
    tracer: PathTracer,
    /// The direct irradiance's pass under `IrradianceSource::Direct`.
    direct: Option<DirectIrradiancePass>,
    profiles: Vec<SssProfile>,
    taa: Option<Taa>,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = SssSettings;
    const NAME: &'static str = "Sss";
    const STATISTICS: &'static [frame::method::Statistic] = crate::recorded::STATISTICS;

    fn label(settings: &SssSettings) -> String {
        settings.label()
    }

    fn spp(settings: &SssSettings) -> f64 {
        settings.spp as f64
    }

    fn temporal_window(_settings: &SssSettings) -> Option<f64> {
        Some(1.0)
    }

    fn set_spp(settings: &mut SssSettings, spp: u32) {
        settings.spp = spp;
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, s: &SssSettings) -> Result<()> {
        if s.spp == 0 {
            bail!("Sss: spp 0; expected at least 1 path-traced sample per pixel");
        }
        s.pass_settings(0).validate().map_err(|e| anyhow::anyhow!("Sss: {e}"))?;
        if let SssVariant::Fixed { count } = s.variant
            && !(1..=crate::gpu::MAX_COUNT).contains(&count)
        {
            bail!("Sss: Fixed count {count}; expected 1 to {}", crate::gpu::MAX_COUNT);
        }
        if let SssVariant::Separable { taps } = s.variant
            && (taps < 3 || taps % 2 == 0 || taps > crate::separable::MAX_TAPS)
        {
            bail!(
                "Sss: Separable taps {taps}; expected an odd count in [3, {}]",
                crate::separable::MAX_TAPS
            );
        }
        let scene = &world.resource::<sim::ExtractedScene>().scene;
        let subsurface: Vec<(u32, scene::Material)> = scene
            .materials
            .iter()
            .enumerate()
            .filter(|(_, m)| m.subsurface.is_some())
            .map(|(i, m)| (i as u32, *m))
            .collect();
        if subsurface.is_empty() {
            bail!(
                "Sss: the scene has no subsurface material; expected a material override in the scenario, e.g. materials: [(material: \"skin\", subsurface: (dmfp: (0.3, 0.12, 0.06)))]"
            );
        }
        if subsurface.len() > MAX_SSS_MATERIALS {
            bail!(
                "Sss: {} subsurface materials; expected at most {MAX_SSS_MATERIALS} (a pass each)",
                subsurface.len()
            );
        }
        let (width, height) = {
            let run = world.resource::<Run>();
            (run.width, run.height)
        };
        let gpu = &world.resource::<GpuDevice>().0;
        let profiles = subsurface
            .iter()
            .map(|&(material, m)| {
                let dmfp = m.subsurface.expect("filtered").dmfp;
                let d = [0, 1, 2]
                    .map(|c| (dmfp[c] as f64 / scaling_from_dmfp(m.base_color[c] as f64)) as f32);
                Ok(SssProfile { material, d, pass: SssPass::new(gpu, width, height)? })
            })
            .collect::<Result<Vec<_>>>()?;
        let gpu_scene = &world.resource::<GpuScene>().0;
        let taa = s.taa.map(|t| Taa::new(gpu, gpu_scene, t)).transpose()?;
        let tracer = PathTracer::new(gpu, gpu_scene)?;
        let direct = match s.irradiance {
            IrradianceSource::Direct => Some(DirectIrradiancePass::new(gpu, gpu_scene)?),
            IrradianceSource::PathTraced => None,
        };
        world.entity_mut(entity).insert(SssState {
            settings: s.clone(),
            tracer,
            direct,
            profiles,
            taa,
        });
        Ok(())
    }
}

/// Path tracing, demodulation, the SSS pass, modulation.
pub fn render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    mut methods: Query<(&mut SssState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let fail = |e: &dyn std::fmt::Display| method_failed(&info.label, clock.global, e);
        let state = &mut *state;
        let out = state
            .tracer
            .render(&gpu.0, &gpu_scene.0, state.settings.spp, run.scenario.seed, clock.global)
            .map_err(|e| fail(&e))?;
        // Pixels per scene unit at distance t: height / (2 t tan(vfov / 2)) (on the axis).
        let focal = out.height as f32 / (2.0 * (0.5 * gpu_scene.0.camera().vfov).tan());
        let g = &out.gbuffer;
        // Per pixel: which profile's material it shows (None: not subsurface).
        let profile_of: Vec<Option<usize>> = g
            .instance_id
            .iter()
            .map(|&inst| {
                let material = (inst != NO_HIT)
                    .then(|| scene.scene.instances.get(inst as usize).map(|x| x.material))
                    .flatten()?;
                state.profiles.iter().position(|p| p.material == material)
            })
            .collect();
        let settings = state.settings.pass_settings(run.scenario.seed);
        let mut timings = out.timings.clone();
        // The demodulated irradiance B(p) the passes scatter, per pixel (rgb).
        let b: Vec<[f32; 3]> = match state.direct.as_mut() {
            Some(direct) => {
                let (e, t) =
                    direct.render(&gpu.0, &gpu_scene.0, clock.global).map_err(|e| fail(&e))?;
                render::timing::merge(&mut timings, t);
                e.iter().map(|e| [e[0], e[1], e[2]]).collect()
            }
            None => (0..out.radiance.len())
                .map(|i| {
                    let (l, a) = (out.radiance[i], Vec3::from(g.albedo[i]).max(Vec3::splat(1e-4)));
                    [l[0] / a.x, l[1] / a.y, l[2] / a.z]
                })
                .collect(),
        };
        let irradiance_sum: f64 = (0..b.len())
            .filter(|&i| profile_of[i].is_some())
            .map(|i| crate::sampling::luminance(b[i]) as f64)
            .sum();
        let mut radiance = out.radiance.clone();
        let mut counts = vec![0u32; radiance.len()];
        for (k, profile) in state.profiles.iter_mut().enumerate() {
            let irradiance: Vec<[f32; 4]> = (0..out.radiance.len())
                .map(|i| {
                    let l = out.radiance[i];
                    if profile_of[i] != Some(k) {
                        return [l[0], l[1], l[2], 0.0];
                    }
                    [b[i][0], b[i][1], b[i][2], focal / g.depth[i].max(1e-6)]
                })
                .collect();
            let sss_frame = SssFrame {
                width: out.width,
                height: out.height,
                irradiance,
                d_px: profile.d,
                focal_px: focal,
                motion: g.motion.clone(),
            };
            render::timing::merge(
                &mut timings,
                profile
                    .pass
                    .dispatch(&gpu.0, &sss_frame, &settings, clock.global)
                    .map_err(|e| fail(&e))?,
            );
            for (i, r) in profile.pass.results(&gpu.0).map_err(|e| fail(&e))?.iter().enumerate() {
                if profile_of[i] == Some(k) {
                    let a = g.albedo[i];
                    radiance[i] = [r.rgb[0] * a[0], r.rgb[1] * a[1], r.rgb[2] * a[2], 1.0];
                    counts[i] = r.count;
                }
            }
        }
        let sss_pixels = profile_of.iter().filter(|p| p.is_some()).count() as u64;
        let count_sum: u64 = counts.iter().map(|&c| c as u64).sum();
        let radiance = match state.taa.as_mut() {
            Some(taa) => {
                let resolved = resolve_taa(&gpu.0, taa, &radiance, g).map_err(|e| fail(&e))?;
                timings.extend(resolved.timings);
                resolved.radiance
            }
            None => radiance,
        };
        let counts = frame::output::grey_pixels(counts.iter().map(|&c| c as f32 / 64.0));
        let mean_spp = count_sum as f64 / sss_pixels.max(1) as f64;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("sss_mean_spp".into(), mean_spp),
                ("sss_pixels".into(), sss_pixels as f64),
                // The mean luminance of B(p) over the subsurface pixels: constant across seeds
                // on a still frame under `Direct`.
                ("sss_irradiance".into(), irradiance_sum / sss_pixels.max(1) as f64),
            ],
            images: vec![MethodImage { name: "sample_count".into(), pixels: counts, hdr: false }],
            ..MethodOutput::timed(
                radiance,
                out.gbuffer.motion.clone(),
                &timings,
                out.rays,
                out.shaded,
            )
        });
        frame.add_cpu(start);
    }
    Ok(())
}

/// taa's resolve over the pass's image: the colour and each pixel's primary hit from
/// the G-buffer (rays through pixel centres: jitter (0.5, 0.5)). The G-buffer has no depth
/// from the previous camera: `previous_depth` is this frame's depth (exact for the static
/// camera and sphere of the SSS scenes; the boids' own pixels are not subsurface).
fn resolve_taa(
    gpu: &render::gpu::Gpu,
    taa: &mut Taa,
    radiance: &[[f32; 4]],
    g: &render::path_tracer::GBuffer,
) -> Result<taa::TaaOutput, render::error::RenderError> {
    let primary: Vec<TaaPrimary> = (0..radiance.len())
        .map(|i| {
            let depth = if g.depth[i].is_finite() { g.depth[i] } else { 0.0 };
            TaaPrimary {
                normal: g.normal[i],
                depth,
                motion: g.motion[i],
                instance: g.instance_id[i],
                previous_depth: depth,
            }
        })
        .collect();
    taa.resolve_colour(gpu, [0.5, 0.5], radiance, &primary)
}
