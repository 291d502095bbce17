//! The failure cases: for each method, a shipped scenario where it fails, which of its methods
//! fails against which baseline, what to look at and why it fails (the papers' own failure cases
//! where they name one).

/// One failure case of `flicker gallery failures`.
#[derive(Clone, Debug)]
pub struct Case {
    /// The case's name: its section anchor, picture and run folder.
    pub name: &'static str,
    /// The method and its guide page, relative to docs/.
    pub method: &'static str,
    pub page: &'static str,
    pub scenario: &'static str,
    /// The labels (frames.csv's `method`) of the failing method and of the baseline beside it.
    pub failing: &'static str,
    pub baseline: &'static str,
    /// The frames.csv columns whose window means the page prints.
    pub columns: &'static [&'static str],
    /// The frame pictured (clamped to the run; the reference frame nearest it where the run has
    /// references).
    pub frame: u32,
    /// The size the gallery plays it at: small enough for lavapipe in a debug build.
    pub resolution: (u32, u32),
    pub frames: u32,
    /// What fails and why.
    pub why: &'static str,
}

/// Every case, in the page's order.
pub const CASES: &[Case] = &[
    Case {
        name: "nirc_dark",
        method: "Nirc",
        page: "methods/nirc.md",
        scenario: "scenarios/nirc_failure_dark.ron",
        failing: "nirc_blend_1spp",
        baseline: "nirc_ema_1spp",
        columns: &["smape", "reliability_high_lr", "reliability_ema", "blend_sigma"],
        frame: 26,
        resolution: (64, 36),
        frames: 32,
        why: "A room lit only through a door gap (the paper's section 5, very dark regions): at one \
              path per pixel almost no training path reaches the light, so the targets are rare \
              fireflies, neither predictor's reliability rises above zero and the blend's σ stays \
              near 0.5, an even mix that cannot prefer the better predictor when the door opens. Both predictors read one cache, so its reliabilities and σ are the same \
              in both rows.",
    },
    Case {
        name: "nirc_glossy",
        method: "Nirc",
        page: "methods/nirc.md",
        scenario: "scenarios/nirc_failure_glossy.ron",
        failing: "nirc_blend_1spp",
        baseline: "nirc_ema_1spp",
        columns: &["smape", "reliability_high_lr", "reliability_ema", "blend_sigma"],
        frame: 26,
        resolution: (64, 36),
        frames: 32,
        why: "The Cornell box turned into rough metal, then its light tilted (section 5, long \
              glossy chains): incident radiance depends on direction more sharply than a small \
              cache resolves from sparse view-dependent targets, so the reliabilities stay low \
              and the blend barely leaves an even mix. Both predictors read one cache, so its reliabilities and σ are the same in \
              both rows.",
    },
    Case {
        name: "nirc_thin",
        method: "Nirc",
        page: "methods/nirc.md",
        scenario: "scenarios/nirc_failure_thin.ron",
        failing: "nirc_blend_1spp",
        baseline: "nirc_ema_1spp",
        columns: &["smape", "reliability_high_lr", "reliability_ema", "blend_sigma"],
        frame: 20,
        resolution: (64, 36),
        frames: 24,
        why: "A turning hairball (section 5, thin geometry): strands are far thinner than a \
              reliability cell, so each cell mixes strands, floor and gaps; as strands move \
              through cells the reliabilities swing from frame to frame and the blend cannot \
              settle. Both predictors read one cache, so its reliabilities and σ are the same in \
              both rows.",
    },
    Case {
        name: "termination_glossy",
        method: "Termination",
        page: "methods/termination.md",
        scenario: "scenarios/termination_failure_glossy.ron",
        failing: "vb_rel_1",
        baseline: "pt",
        columns: &["flip", "smape", "path_length"],
        frame: 0,
        resolution: (64, 36),
        frames: 4,
        why: "Rough metal in the Cornell box (the paper's Fig. 12, glossy bias): a cache record \
              holds one radiance per voxel, averaged over the directions its vertices were \
              reached from, so a path that terminates into it on a glossy surface gets the \
              surface's mean outgoing radiance instead of the reflection it sees: reflections \
              blur and darken against path tracing of the same paths.",
    },
    Case {
        name: "taa_fast_turn",
        method: "Taa",
        page: "methods/taa.md",
        scenario: "scenarios/fast_turn.ron",
        failing: "taa",
        baseline: "pt_4spp",
        columns: &["flip", "smape"],
        frame: 21,
        resolution: (64, 36),
        frames: 24,
        why: "A still courtyard, then the camera turns 60° a frame: every pixel's history \
              reprojects off-screen or onto a surface not seen before and is rejected, so TAA \
              falls back to its one new sample per pixel (the error jumps towards 1 spp) and \
              needs several frames to converge again.",
    },
    Case {
        name: "hash_cache_hairball",
        method: "HashCache",
        page: "methods/hash-cache.md",
        scenario: "scenarios/hairball_camera.ron",
        failing: "hash_cache_taa",
        baseline: "ssc_adaptive_taa",
        columns: &["flip", "smape"],
        frame: 23,
        resolution: (64, 36),
        frames: 24,
        why: "A camera sliding round thin crossing strands (the stable-sample-caching paper's \
              hard case): a first-hit voxel spans several strands and the gaps between them, so \
              the world-space cache averages light from surfaces that do not see the same light, \
              and TAA's reprojection of strands that move across pixels smears them.",
    },
];
