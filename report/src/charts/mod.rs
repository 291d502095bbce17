//! Charts of a run: a small plot model (series, events, Pareto front) drawn by plotters to SVG
//! and PNG (`plot`), both with title, axis labels and legend.

pub mod build;
pub mod plot;

/// Plot size in pixels (both renderers).
pub const WIDTH: u32 = 720;
pub const HEIGHT: u32 = 400;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// One polyline per series (metric against frame).
    Lines,
    /// One marker per point (speed against accuracy).
    Scatter,
}

#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub kind: Kind,
    pub series: Vec<Series>,
    /// Vertical markers: (x, label), e.g. scripted events.
    pub events: Vec<(f64, String)>,
    /// Points of the Pareto front, drawn as a polyline (scatter charts).
    pub pareto: Vec<(f64, f64)>,
    /// x values the axis must cover besides the data (e.g. the whole frame range).
    pub x_extent: Vec<f64>,
}

/// Distinguishable colours (Okabe-Ito, colour-blind safe), cycled.
pub fn color(i: usize) -> [u8; 3] {
    const C: [[u8; 3]; 7] = [
        [0, 114, 178],
        [230, 159, 0],
        [0, 158, 115],
        [204, 121, 167],
        [86, 180, 233],
        [213, 94, 0],
        [120, 120, 120],
    ];
    C[i % C.len()]
}

/// Points not dominated by any other when both coordinates are minimised (cost and error),
/// sorted by x.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> =
        points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if front.last().is_none_or(|last| q.1 < last.1) {
            front.push(q);
        }
    }
    front
}

/// Axis range and ticks.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub min: f64,
    pub max: f64,
    pub ticks: Vec<f64>,
}

impl Axis {
    /// A padded range with "nice" ticks (1, 2, 5 × 10^k) covering `values`; starts at 0 when
    /// the data are non-negative and reach well above it.
    pub fn fit(values: impl Iterator<Item = f64>, include_zero: bool) -> Self {
        let (mut lo, mut hi) = values
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        if include_zero && lo >= 0.0 && lo < 0.5 * hi {
            lo = 0.0;
        }
        if hi - lo < 1e-12 {
            let pad = if hi.abs() > 0.0 { hi.abs() * 0.1 } else { 1.0 };
            (lo, hi) = (lo - pad, hi + pad);
        }
        let raw = (hi - lo) / 5.0;
        let mag = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * mag)
            .find(|s| *s >= raw)
            .unwrap_or(10.0 * mag);
        let min = (lo / step).floor() * step;
        let max = (hi / step).ceil() * step;
        let n = ((max - min) / step).round() as usize;
        let ticks = (0..=n).map(|i| min + i as f64 * step).collect();
        Self { min, max, ticks }
    }
}

/// The axes' ranges of a chart.
#[derive(Clone, Debug)]
pub struct Frame {
    pub x: Axis,
    pub y: Axis,
}

impl Frame {
    pub fn of(chart: &Chart) -> Self {
        let pts = || chart.series.iter().flat_map(|s| s.points.iter().copied());
        let xs = pts()
            .map(|p| p.0)
            .chain(chart.events.iter().map(|e| e.0))
            .chain(chart.x_extent.iter().copied());
        let x = Axis::fit(xs, chart.kind == Kind::Scatter);
        let y = Axis::fit(pts().map(|p| p.1), true);
        Self { x, y }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_minimises_both() {
        let pts = [(1.0, 0.5), (2.0, 0.3), (3.0, 0.4), (4.0, 0.1), (0.5, 0.9), (2.0, 0.35)];
        assert_eq!(pareto_front(&pts), vec![(0.5, 0.9), (1.0, 0.5), (2.0, 0.3), (4.0, 0.1)]);
    }

    #[test]
    fn nice_axis() {
        let a = Axis::fit([0.13, 0.91].into_iter(), true);
        assert_eq!((a.min, a.max), (0.0, 1.0));
        assert_eq!(a.ticks.len(), 6);
        let b = Axis::fit([31.2, 38.9].into_iter(), true);
        assert!(b.min <= 31.2 && b.max >= 38.9 && b.min > 0.0);
        let c = Axis::fit([2.0, 2.0].into_iter(), false);
        assert!(c.min < 2.0 && c.max > 2.0);
    }
}
