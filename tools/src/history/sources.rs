//! What each command contributes to the results history: a reproduce run's claims (value,
//! interval, verdict, margin), a suite run's gates, and the bench's side-by-side ratios.

use std::path::Path;

use crate::reproduce::claims::{Claim, Comparison};
use crate::reproduce::effect::Effect;
use crate::reproduce::log_ratio::RatioExpectation;
use crate::reproduce::verdict::{Judged, bounds};
use crate::suite::gate::{GateResult, Verdict as GateVerdict};
use crate::suite::welch::Sample;

use super::record::Entry;

/// A value and its interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
}

fn estimate(values: &[f64], confidence: f64) -> Option<Estimate> {
    if values.len() < 2 || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // The judge's own interval: one-sided bounds at the claim's confidence.
    let (mean, lo, hi) = bounds(values, confidence);
    Some(Estimate { value: mean, lo, hi })
}

/// The two halves of a relation's per-seed values (`Judged::values`: the first method's, then
/// the second's), or none.
fn halves(v: &[f64]) -> Option<(&[f64], &[f64])> {
    let n = v.len() / 2;
    v.len().is_multiple_of(2).then(|| (&v[..n], &v[n..]))
}

/// The number a claim is judged on, from its per-seed values (`Judged::values`): a relation's
/// mean paired difference (`Below`, `NotAbove`, `Rises`: first minus second), a log ratio's
/// geometric mean ratio, otherwise the mean of the per-seed values, ratios or differences; with
/// the judge's interval at the claim's confidence.
pub fn claim_estimate(comparison: &Comparison, judged: &Judged) -> Option<Estimate> {
    let v = &judged.values;
    match comparison {
        Comparison::Below { confidence, .. }
        | Comparison::NotAbove { confidence, .. }
        | Comparison::Rises { confidence, .. } => {
            let (a, b) = halves(v)?;
            let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
            estimate(&d, *confidence)
        }
        Comparison::LogRatio { confidence, .. } => {
            let (a, b) = halves(v)?;
            let logs: Vec<f64> = a.iter().zip(b).map(|(x, y)| (x / y).ln()).collect();
            let e = estimate(&logs, *confidence)?;
            Some(Estimate { value: e.value.exp(), lo: e.lo.exp(), hi: e.hi.exp() })
        }
        Comparison::Value { confidence, .. }
        | Comparison::Ratio { confidence, .. }
        | Comparison::Difference { confidence, .. } => estimate(v, *confidence),
        Comparison::NotComparable { .. } => None,
    }
}

/// The smallest change of a claim's value that matters, and where it comes from: the claim's
/// own smallest effect (`smallest_effect`, stated from the paper or an argued threshold), in
/// the unit of `claim_estimate`'s value. A relative one is a share of the judge's base: the
/// second method's mean for a relation, the paper's value for a value, ratio or difference,
/// the factor for a log ratio. None when the base is not known (no values).
pub fn claim_margin(claim: &Claim, judged: &Judged) -> (Option<f64>, String) {
    let base = match &claim.comparison {
        Comparison::Below { .. } | Comparison::NotAbove { .. } | Comparison::Rises { .. } => {
            halves(&judged.values).filter(|(_, b)| !b.is_empty()).map(|(_, b)| Sample::of(b).mean)
        }
        Comparison::Value { value, .. }
        | Comparison::Ratio { value, .. }
        | Comparison::Difference { value, .. } => Some(*value),
        Comparison::LogRatio { expect: RatioExpectation::Below(f), .. }
        | Comparison::LogRatio { expect: RatioExpectation::Near(f), .. } => Some(*f),
        Comparison::NotComparable { .. } => None,
    };
    let margin = match claim.smallest_effect {
        Effect::Absolute(d) => Some(d),
        Effect::Relative(_) => base.map(|b| claim.smallest_effect.margin(b)),
    };
    (margin, claim.smallest_effect_from.clone())
}

/// A reproduce run's entry for one claim of `paper`.
pub fn claim_entry(paper: &str, claim: &Claim, judged: &Judged) -> Entry {
    let e = claim_estimate(&claim.comparison, judged);
    let (margin, margin_from) = claim_margin(claim, judged);
    Entry {
        id: format!("{paper}/{}", claim.id),
        value: e.map(|e| e.value),
        lo: e.map(|e| e.lo),
        hi: e.map(|e| e.hi),
        verdict: Some(judged.verdict.name().to_string()),
        margin,
        margin_from,
        detail: judged.flicker.clone(),
    }
}

/// A suite run's entry for one gate result: the new runs' mean and 95% interval over seeds.
pub fn gate_entry(r: &GateResult) -> Entry {
    let e = r.new.filter(|s| s.n >= 2).map(|s| {
        let t = crate::suite::student_t::quantile(0.975, (s.n - 1) as f64);
        let half = t * s.standard_error();
        Estimate { value: s.mean, lo: s.mean - half, hi: s.mean + half }
    });
    let verdict = match r.verdict {
        GateVerdict::Pass => "pass",
        GateVerdict::Fail => "fail",
        GateVerdict::Error(_) => "error",
    };
    Entry {
        id: format!("{}/{}/{}", r.case, r.method, r.gate),
        value: e.map(|e| e.value).or(r.new.map(|s| s.mean)),
        lo: e.map(|e| e.lo),
        hi: e.map(|e| e.hi),
        verdict: Some(verdict.into()),
        margin: e.map(|e| (e.hi - e.lo) / 2.0),
        margin_from: "the half-width of the run's interval".into(),
        detail: r.detail.clone(),
    }
}

fn ratio(id: String, value: Option<f64>, rounds: &[f64], detail: &str) -> Option<Entry> {
    let value = value.filter(|v| v.is_finite())?;
    let (lo, hi) = if rounds.len() >= 2 {
        let lo = rounds.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = rounds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (Some(lo), Some(hi))
    } else {
        (None, None)
    };
    Some(Entry {
        id,
        value: Some(value),
        lo,
        hi,
        verdict: None,
        margin: lo.zip(hi).map(|(l, h)| (h - l) / 2.0),
        margin_from: if lo.is_some() {
            "half the range of the run's rounds".into()
        } else {
            "the spread of repeated runs at one commit".into()
        },
        detail: detail.into(),
    })
}

/// The numbers of a JSON array (none where it is missing).
fn numbers(array: &serde_json::Value) -> Vec<f64> {
    array.as_array().into_iter().flatten().filter_map(|v| v.as_f64()).collect()
}

/// The bench's side-by-side ratios from `flicker bench --json`'s speed report: WGSL traversal
/// over obvhs on the CPU per scene and the reference path tracer's paths per second over
/// Mitsuba 3's, each with its paired rounds.
pub fn bench_speed_entries(json: &serde_json::Value) -> Vec<Entry> {
    let mut out = Vec::new();
    for row in json["traversal"].as_array().into_iter().flatten() {
        let scene = row["scene"].as_str().unwrap_or("?");
        out.extend(ratio(
            format!("traversal/{scene}/wgsl_over_obvhs"),
            row["traversal_ratio_vs_obvhs"].as_f64(),
            &numbers(&row["paired_ratios"]),
            "WGSL CWBVH rays/s over obvhs CPU rays/s, median of paired rounds",
        ));
    }
    // Records from before the paired rounds have none: their spread comes from repeated runs.
    out.extend(ratio(
        "reference/paths_over_mitsuba".into(),
        json["reference_paths_ratio_vs_mitsuba"].as_f64(),
        &numbers(&json["reference_paired_ratios_vs_mitsuba"]),
        "reference path tracer paths/s over Mitsuba 3 scalar_rgb, median of paired rounds",
    ));
    out
}

/// The image-metric bench's ratio: NVIDIA's flip-evaluator time over flicker's HDR-FLIP time.
pub fn bench_metrics_entries(json: &serde_json::Value) -> Vec<Entry> {
    ratio(
        "metrics/flip_evaluator_over_flicker".into(),
        json["speedup"].as_f64(),
        &[],
        "NVIDIA flip-evaluator HDR-FLIP time over flicker's",
    )
    .into_iter()
    .collect()
}

/// The adapter of the first run folder under `folder` (its manifest.json), or `fallback`.
pub fn adapter_of_runs(folder: &Path, fallback: &str) -> String {
    fn find(dir: &Path, depth: usize) -> Option<String> {
        let m = dir.join("manifest.json");
        if let Ok(text) = std::fs::read_to_string(&m) {
            let v: serde_json::Value = serde_json::from_str(&text).ok()?;
            let a = &v["adapter"];
            return Some(format!(
                "{} / {}",
                a["name"].as_str().unwrap_or("?"),
                a["backend"].as_str().unwrap_or("?")
            ));
        }
        if depth == 0 {
            return None;
        }
        let mut subs: Vec<_> = std::fs::read_dir(dir).ok()?.flatten().map(|e| e.path()).collect();
        subs.sort();
        subs.into_iter().filter(|p| p.is_dir()).find_map(|p| find(&p, depth - 1))
    }
    find(folder, 4).unwrap_or_else(|| fallback.to_string())
}
