//! What a method declares it records, beside the numbers every method has (FLIP, SMAPE, PSNR,
//! JOD, times, rays): its statistics and its charts. A method lists them in its own folder
//! (`MethodPlugin::STATISTICS`, `MethodPlugin::CHARTS`); suites and `flicker reproduce` find a
//! statistic by its name through the registry, and the report draws the charts of every
//! registered method whose columns a run has; a statistic computed from a run folder's images
//! carries the method's own function ([`FolderStatistic`]). Data and function pointers, so
//! that the crates reading run folders need no method crate.

use std::path::Path;

/// Which way a statistic is better.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Better {
    Lower,
    Higher,
}

/// What a statistic computed from a run folder needs of its claim and case, checked when a
/// claims file loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FolderInput {
    /// Another method of the same run to compare with: the claim's `against`.
    Against,
    /// The case's first event, and methods whose settings write the image map `map`
    /// (`MethodPlugin::writes_image`); `writers` says which do, for errors
    /// (`a blend or the switch`).
    EventAndMap { map: &'static str, writers: &'static str },
    /// Every frame of the run: one number per run (its mean over the Overall window), so
    /// neither a suite nor `by_window` reads it.
    WholeRun,
}

/// A run folder as a [`FolderStatistic`] reads it.
#[derive(Clone, Copy, Debug)]
pub struct FolderRun<'a> {
    /// The run folder (`frame::run_folder::RunFolder`'s root).
    pub folder: &'a Path,
    /// The run's seed, for errors.
    pub seed: u64,
    /// The run's method labels.
    pub methods: &'a [String],
    /// The run's recorded frames.
    pub frames: u32,
    /// The case's events, in recorded frames.
    pub events: &'a [u32],
    /// The claim's `against` method (with [`FolderInput::Against`]).
    pub against: Option<&'a str>,
}

/// What a [`FolderStatistic`] computed: per method label and column, the per-frame values.
pub type FolderSeries = Vec<(String, &'static str, Vec<Option<f64>>)>;

/// A statistic `flicker reproduce` computes from a run folder's images (and frames.csv), the
/// computation living in the method crate that declares it.
#[derive(Clone, Copy)]
pub struct FolderStatistic {
    /// Names the computation: the statistics one computation fills (σ where the reference
    /// changed most and least) share it, and it runs once per case.
    pub id: &'static str,
    pub input: FolderInput,
    pub compute: fn(&FolderRun) -> anyhow::Result<FolderSeries>,
}

/// The same computation: the same `id` and input (function addresses are not compared, they
/// may differ between codegen units).
impl PartialEq for FolderStatistic {
    fn eq(&self, other: &Self) -> bool {
        self.id == other.id && self.input == other.input
    }
}

impl Eq for FolderStatistic {}

impl std::fmt::Debug for FolderStatistic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FolderStatistic").field("id", &self.id).field("input", &self.input).finish()
    }
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
    /// Computed by `flicker reproduce` from the run folder's images, by the method's code.
    Images(FolderStatistic),
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
