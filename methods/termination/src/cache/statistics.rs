//! What a frame counts on the GPU and what the records hold: the counters' words and the
//! statistics over the filled records.

use super::gpu_types::TcRecord;
use crate::moments::RecordMoments;
use glam::Vec3;
use render::lights::luminance;

/// Words of `counters` (termination.wgsl's TC_COUNTER_*).
pub(super) const COUNTERS: u64 = 10;
/// Words of `counters` a trace writes (path vertices, trace rays, unknown records): a tracer's
/// own; every other word counts the cache's passes.
pub(super) const TRACE_COUNTERS: [u64; 3] = [0, 1, 6];

/// Counters of one frame (counted on the GPU).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TerminationStats {
    /// Surface vertices of the tracer's paths, all pixels, in 1/256 vertex (the vertex after a
    /// blend counts α).
    pub path_vertices: u32,
    pub trace_rays: u32,
    pub propagate_rays: u32,
    /// New keys given a slot, and insertion requests refused (a full probe window). Counted by
    /// the insertion after the image: 0 in [`TerminationCache::trace`]'s output, counted in
    /// [`TerminationCache::render`]'s and [`TerminationCache::read_counters`] after the store.
    ///
    /// [`TerminationCache::trace`]: super::TerminationCache::trace
    /// [`TerminationCache::render`]: super::TerminationCache::render
    /// [`TerminationCache::read_counters`]: super::TerminationCache::read_counters
    pub inserted: u32,
    pub insert_failures: u32,
    /// Vertices `tc_store` kept. It runs after the image ([`TerminationCache::store`]): 0 in
    /// [`TerminationCache::trace`]'s output, counted in [`TerminationCache::render`]'s.
    ///
    /// [`TerminationCache::store`]: super::TerminationCache::store
    /// [`TerminationCache::trace`]: super::TerminationCache::trace
    /// [`TerminationCache::render`]: super::TerminationCache::render
    pub stored: u32,
    /// Decisions at a vertex whose record was absent or empty (the path continued).
    pub unknown: u32,
    /// Stored vertices propagated whose samples all read a filled record.
    pub propagated: u32,
    /// Stored vertices propagated with a sample that read no filled record (they only start
    /// empty records).
    pub incomplete: u32,
    /// Records holding moments after this frame's fold.
    pub filled: u32,
}

/// Means over the filled records (luminance) of the statistics the rules read: how fast the
/// cache follows a change in the scene, and why termination moves meanwhile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CacheStatistics {
    /// E[Y]: the cache value.
    pub mean: f64,
    /// E[Y²] − E[E[Y|y]²]: average variance of one more segment.
    pub variance: f64,
    /// E[E[Y|y]²] − E[Y]²: average squared bias of terminating into the record.
    pub bias2: f64,
    /// Quantiles over the filled records of their variance (10%, 50%, 90%): where an absolute
    /// threshold lies against the scene's local variances.
    pub variance_quantiles: [f64; 3],
    /// Quantiles over the filled records of their value E[Y] (10%, 50%, 90%).
    pub mean_quantiles: [f64; 3],
}

impl CacheStatistics {
    /// Over the records holding moments; zeros for an empty cache.
    pub fn of(records: &[TcRecord]) -> Self {
        let filled: Vec<RecordMoments> = records
            .iter()
            .filter(|r| r.vertices > 0.0)
            .map(|r| RecordMoments {
                vertices: r.vertices as f64,
                mean: luminance(Vec3::from(r.mean)) as f64,
                second: r.second as f64,
                marginal: r.marginal as f64,
                mean_sq: r.mean_sq as f64,
                weight2: r.weight2 as f64,
            })
            .collect();
        let n = filled.len().max(1) as f64;
        let quantiles = |value: fn(&RecordMoments) -> f64| {
            let mut v: Vec<f64> = filled.iter().map(value).collect();
            v.sort_by(f64::total_cmp);
            [0.1, 0.5, 0.9].map(|q| v.get((q * v.len() as f64) as usize).copied().unwrap_or(0.0))
        };
        Self {
            mean: filled.iter().map(|m| m.mean).sum::<f64>() / n,
            variance: filled.iter().map(|m| m.average_variance()).sum::<f64>() / n,
            bias2: filled.iter().map(|m| m.squared_bias()).sum::<f64>() / n,
            variance_quantiles: quantiles(RecordMoments::average_variance),
            mean_quantiles: quantiles(|m| m.mean),
        }
    }
}

/// The counters' words as statistics.
pub(super) fn stats_of(c: &[u32]) -> TerminationStats {
    TerminationStats {
        path_vertices: c[0],
        trace_rays: c[1],
        propagate_rays: c[2],
        inserted: c[3],
        insert_failures: c[4],
        stored: c[5],
        unknown: c[6],
        propagated: c[7],
        incomplete: c[8],
        filled: c[9],
    }
}
