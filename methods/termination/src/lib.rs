//! Hashed radiance cache with variance-trading path termination
//! (../shared/seeds/variance-trading-termination.txt, Kandlbinder, Dittebrandt et al. 2024).
//!
//! CPU reference of the paper's math: the record's three moments (`moments`), the termination
//! rules a scenario selects (`rule`), the decision at a path vertex (`decision`), and the
//! paper's discrete sampling trees of Figs. 4 and 5 in closed form (`sampling_tree`).

pub mod cache;
pub mod decision;
pub mod figures;
pub mod gpu_decision;
pub mod moments;
pub mod rule;
pub mod sampling_tree;
pub mod settings;
pub mod variance_bound;

pub use cache::{
    CacheStatistics, TcPass, TerminationCache, TerminationOutput, TerminationStats,
    TerminationTracer,
};
pub use decision::{Decision, LocalStats, PathState, arrive_area_spread, decide, path_threshold};
pub use moments::{RecordMoments, vertex_estimates};
pub use rule::TerminationRule;
pub use sampling_tree::{Moments, SamplingTree};
pub use settings::{Incomplete, RadianceScale, TerminationSettings};

pub mod plugin;
pub mod recorded;
pub use plugin::Plugin;
