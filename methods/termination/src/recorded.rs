//! What the termination method records besides every method's numbers: its paths' length, its
//! cache's statistics around a change of lighting, and Fig. 7's image variance over its bound
//! (variance-trading-termination.txt); the report charts the per-frame ones.

use frame::method::{FolderInput, FolderStatistic, MethodChart, Source, Statistic};

/// A statistic of the cache's filled records, read back from frames.csv by `flicker reproduce`
/// only (suites' runs and baselines keep their columns without them).
const fn cache(name: &'static str, column: &'static str, label: &'static str) -> Statistic {
    Statistic { source: Source::FramesReproduceOnly, ..Statistic::frames(name, column, label, "") }
}

pub const STATISTICS: &[Statistic] = &[
    // Shorter is "better": `Better(than: M)` on it says the method's paths are shorter than M's.
    Statistic::frames("PathLength", "path_length", "mean path length", "vertices"),
    // E[Y] over the filled records, then the means of E[Y²] − E[E[Y|y]²] and E[E[Y|y]²] − E[Y]².
    cache("CacheMean", "cache_mean", "cache: mean record luminance E[Y]"),
    cache("CacheVariance", "cache_variance", "cache: mean record variance"),
    cache("CacheBias2", "cache_bias2", "cache: mean record squared bias"),
    // Fig. 7: per frame, the mean over pixels of the squared deviation of the frame's luminance
    // from the pixel's mean over the run's frames, times n/(n − 1), over the method's absolute
    // threshold t · unit² (frames.csv's `variance_bound_log10`); over a static scene's run
    // (window Overall) the estimator's per-pixel variance over the bound (`variance_bound.rs`).
    Statistic {
        source: Source::Images(FolderStatistic {
            id: "variance_over_bound",
            input: FolderInput::WholeRun,
            compute: crate::variance_bound::variance_over_bound,
        }),
        ..Statistic::frames(
            "VarianceOverBound",
            crate::variance_bound::COLUMN,
            "image variance over its bound",
            "",
        )
    },
];

/// How termination and the records' statistics move around an event.
pub const CHARTS: &[MethodChart] = &[
    MethodChart::Column { column: "path_length", label: "mean path length (vertices)" },
    MethodChart::Column { column: "cache_mean", label: "cache: mean record luminance E[Y]" },
    MethodChart::Column { column: "cache_variance", label: "cache: mean record variance" },
    MethodChart::Column { column: "cache_bias2", label: "cache: mean record squared bias" },
];
