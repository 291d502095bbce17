//! What NIRC records besides every method's numbers: the blend weight σ per frame and per
//! region of change (claims and suites name them), and the report's charts of reliability and
//! σ (Figure 1 of reliability-weighted-nirc.txt; what σ does and why it stays near 0.5).

use frame::method::{ChartSeries, FolderInput, FolderStatistic, MethodChart, Source, Statistic};

/// σ by region: the mean of the preference maps over the fifth of the pixels whose reference
/// changed most across the case's first event, and over the fifth that changed least; one
/// computation (`sigma_regions.rs`) fills both.
const fn sigma_region(name: &'static str, column: &'static str, label: &'static str) -> Statistic {
    Statistic {
        source: Source::Images(FolderStatistic {
            id: "sigma_by_region",
            input: FolderInput::EventAndMap { map: "preference", writers: "a blend or the switch" },
            compute: crate::sigma_regions::sigma_by_region,
        }),
        needs_references: true,
        ..Statistic::frames(name, column, label, "")
    }
}

pub const STATISTICS: &[Statistic] = &[
    // Mean blend weight σ of the High-LR side over the image (the `blend_sigma` stat).
    Statistic::frames("BlendSigma", "blend_sigma", "mean blend weight σ of High-LR", ""),
    sigma_region(
        "SigmaChanged",
        crate::sigma_regions::CHANGED,
        "mean σ where the reference changed most",
    ),
    sigma_region(
        "SigmaUnchanged",
        crate::sigma_regions::UNCHANGED,
        "mean σ where the reference changed least",
    ),
];

pub const CHARTS: &[MethodChart] = &[
    // Figure 1: mean reliability per frame of the two predictors (every NIRC method of a cache
    // reports the same values, so the first method with data is drawn).
    MethodChart::Columns {
        stem: "frames_reliability",
        title: "Mean reliability per predictor",
        y_label: "mean reliability r̄",
        series: &[
            ChartSeries { column: "reliability_high_lr", legend: "High-LR", required: true },
            ChartSeries { column: "reliability_ema", legend: "EMA", required: true },
        ],
        lines: &[],
    },
    // What σ does: the blend rule's mean σ per frame and the share of queries with σ > 0.5,
    // against the even mixture σ = 0.5.
    MethodChart::Columns {
        stem: "frames_sigma",
        title: "Weight σ of the High-LR predictor",
        y_label: "σ",
        series: &[
            ChartSeries { column: "blend_sigma", legend: "mean σ (blend rule)", required: true },
            ChartSeries {
                column: "prefer_high_lr",
                legend: "share of queries with σ > 0.5",
                required: false,
            },
        ],
        lines: &[(0.5, "σ = 0.5 (even mixture)")],
    },
    // Why σ stays near 0.5 or not: per frame, percentiles over the queries of
    // d = r̄_cur − r̄_EMA, of which σ = 1 / (1 + e^(−κd)) is a function, and the share of
    // queries with |σ − 0.5| > 0.1.
    MethodChart::Columns {
        stem: "frames_reliability_spread",
        title: "Spread of the reliability difference",
        y_label: "r̄_cur − r̄_EMA; share",
        series: &[
            ChartSeries {
                column: "reliability_diff_p10",
                legend: "10th percentile of r̄_cur − r̄_EMA",
                required: false,
            },
            ChartSeries { column: "reliability_diff_p50", legend: "median", required: true },
            ChartSeries {
                column: "reliability_diff_p90",
                legend: "90th percentile",
                required: false,
            },
            ChartSeries {
                column: "sigma_far_from_even",
                legend: "share of queries with |σ − 0.5| > 0.1",
                required: false,
            },
        ],
        lines: &[(0.0, "0")],
    },
];

#[cfg(test)]
mod tests {
    use std::path::Path;

    use metrics::frames_csv::Frames;
    use report::charts::build::method_chart;
    use report::run::Manifest;

    use super::*;

    fn chart(stem: &str) -> &'static MethodChart {
        CHARTS.iter().find(|c| c.stem() == stem).expect(stem)
    }

    #[test]
    fn sigma_and_reliability_charts_follow_the_nirc_columns() {
        let sigma_chart = |m: &Manifest, f: &Frames| method_chart(m, f, chart("frames_sigma"));
        let reliability_chart =
            |m: &Manifest, f: &Frames| method_chart(m, f, chart("frames_reliability"));
        let reliability_spread_chart =
            |m: &Manifest, f: &Frames| method_chart(m, f, chart("frames_reliability_spread"));
        let csv = "method,frame,cpu_ms,reliability_high_lr,reliability_ema,blend_sigma,prefer_high_lr\n\
                   pt_1spp,0,1,,,,\nnirc_blend_1spp,0,2,0.5,0.6,0.45,0.2\nnirc_blend_1spp,1,2,0.4,0.3,0.55,0.7\n";
        let frames = Frames::parse(csv, Path::new("frames.csv")).unwrap();
        let manifest: Manifest = serde_json::from_str(r#"{"scenario": "s", "frames": 2}"#).unwrap();
        let (stem, chart) = sigma_chart(&manifest, &frames).expect("a σ chart");
        assert_eq!(stem, "frames_sigma");
        assert!(chart.title.contains("nirc_blend_1spp"));
        assert_eq!(chart.series[0].points, vec![(0.0, 0.45), (1.0, 0.55)]);
        assert_eq!(chart.series[1].points, vec![(0.0, 0.2), (1.0, 0.7)]);
        assert_eq!(chart.series[2].points, vec![(0.0, 0.5), (1.0, 0.5)]);
        let (_, r) = reliability_chart(&manifest, &frames).expect("a reliability chart");
        assert_eq!(r.series[1].points, vec![(0.0, 0.6), (1.0, 0.3)]);
        assert!(
            reliability_spread_chart(&manifest, &frames).is_none(),
            "no spread columns, no chart"
        );
        let spread = "method,frame,cpu_ms,reliability_diff_p10,reliability_diff_p50,reliability_diff_p90,sigma_far_from_even\n\
                      pt_1spp,0,1,,,,\nnirc_blend_1spp,0,2,-0.1,0.0,0.2,0.3\nnirc_blend_1spp,1,2,-0.2,0.1,0.3,0.4\n";
        let spread = Frames::parse(spread, Path::new("frames.csv")).unwrap();
        let (stem, chart) = reliability_spread_chart(&manifest, &spread).expect("a spread chart");
        assert_eq!(stem, "frames_reliability_spread");
        assert_eq!(chart.series[0].points, vec![(0.0, -0.1), (1.0, -0.2)]);
        assert_eq!(chart.series[2].points, vec![(0.0, 0.2), (1.0, 0.3)]);
        assert_eq!(chart.series[3].points, vec![(0.0, 0.3), (1.0, 0.4)]);
        // A run without NIRC methods has neither chart.
        let plain =
            Frames::parse("method,frame,cpu_ms\npt_1spp,0,1\n", Path::new("frames.csv")).unwrap();
        assert!(
            sigma_chart(&manifest, &plain).is_none()
                && reliability_chart(&manifest, &plain).is_none()
        );
    }
}
