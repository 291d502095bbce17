//! What a method declares it records, beside the numbers every method has (FLIP, SMAPE, PSNR,
//! JOD, times, rays): its statistics and its charts. A method lists them in its own folder
//! (`MethodPlugin::STATISTICS`, `MethodPlugin::CHARTS`); suites and `flicker reproduce` find a
//! statistic by its name through the registry, and the report draws the charts of every
//! registered method whose columns a run has. Plain data, so that the crates reading run
//! folders need no method crate.

/// Which way a statistic is better.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Better {
    Lower,
    Higher,
}

/// How `flicker reproduce` computes a statistic from a run's images (the computations live in
/// `tools::reproduce`; a statistic names the one it needs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageStatistic {
    /// Per frame, the PSNR of the statistic's method against the frames of another method of
    /// the same run, the claim's `against` (`reproduce::sss_psnr`).
    PsnrAgainst,
    /// Per frame, the mean of the method's preference maps over the pixels whose reference
    /// changed most (`changed`) or least across the case's first event
    /// (`reproduce::sigma_regions`).
    PreferenceRegions,
    /// Per frame, the image variance over the pixel's mean across the run, over the method's
    /// bound (`reproduce::variance_bound`); its mean over a static run's frames is the
    /// estimator's variance over the bound.
    VarianceOverBound,
}

/// Where a statistic's per-frame values come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The method's frames.csv column (one of its `MethodOutput::stats`); suites, sweeps and
    /// baselines keep it.
    Frames,
    /// A frames.csv column that only `flicker reproduce` reads: suites' runs, sweeps and
    /// baselines keep their columns without it.
    FramesReproduceOnly,
    /// Computed by `flicker reproduce` from the run folder's images.
    Images(ImageStatistic),
}

/// One statistic a method records: per frame, so a window's value is the mean of its frames'
/// (frames without a value left out).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Statistic {
    /// The name claims and suites write (`metric: PathLength`), unique over the registry.
    pub name: &'static str,
    /// Its key: the frames.csv column (the method's stat) and the series' name in suites,
    /// baselines and reproduce's tables, e.g. `path_length`.
    pub column: &'static str,
    /// What it is, for a chart's axis and a table: `mean path length`.
    pub label: &'static str,
    /// Its unit (`vertices`, `dB`, `` for a ratio).
    pub unit: &'static str,
    pub better: Better,
    pub source: Source,
    /// Recorded only in runs whose scenario has reference frames.
    pub needs_references: bool,
}

impl Statistic {
    /// A frames.csv column every suite keeps, lower better, in any run.
    pub const fn frames(
        name: &'static str,
        column: &'static str,
        label: &'static str,
        unit: &'static str,
    ) -> Self {
        Statistic {
            name,
            column,
            label,
            unit,
            better: Better::Lower,
            source: Source::Frames,
            needs_references: false,
        }
    }
}

/// One line of a [`MethodChart::Columns`] chart: a frames.csv column of the method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChartSeries {
    pub column: &'static str,
    pub legend: &'static str,
    /// Without data in this column the chart is not drawn; the chart's method is the first
    /// with data in its first required column.
    pub required: bool,
}

/// A chart against frame that a method's columns get in the report (`charts/STEM.svg`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MethodChart {
    /// `frames_COLUMN`: the column against frame, one line per method, as FLIP and SMAPE are
    /// drawn; `label` names the axis and the title.
    Column { column: &'static str, label: &'static str },
    /// Several columns of one method (the first with data, named in the title), with
    /// horizontal reference lines `(y, legend)`; every method of a shared cache reports the same
    /// values, so one method's lines are drawn.
    Columns {
        stem: &'static str,
        title: &'static str,
        y_label: &'static str,
        series: &'static [ChartSeries],
        lines: &'static [(f64, &'static str)],
    },
}

impl MethodChart {
    /// The file stem of the chart, `frames_COLUMN` or the given one.
    pub fn stem(&self) -> String {
        match self {
            MethodChart::Column { column, .. } => format!("frames_{column}"),
            MethodChart::Columns { stem, .. } => stem.to_string(),
        }
    }
}
