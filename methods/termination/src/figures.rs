//! The paper's sampling-tree figures as claims compute them: exact moments of the estimator on
//! the trees of Figs. 4 and 5 (albedo 0.9, left child 90%), no Monte Carlo.

use std::collections::BTreeMap;

use frame::computation::load;
use frame::method::{Computed, ComputedValues, DeclaredComputation};
use serde::Deserialize;

use crate::rule::{TerminationRule, default_bias_clamp, default_margin};
use crate::sampling_tree::SamplingTree;

/// Figs. 4 and 5, by the names claims files write.
pub const COMPUTATIONS: &[DeclaredComputation] = &[
    DeclaredComputation { name: "TerminationFig4", load: load::<TerminationFig4> },
    DeclaredComputation { name: "TerminationFig5", load: load::<TerminationFig5> },
];

const TREE_ALBEDO: f64 = 0.9;

/// Fig. 4: variance bounding on the exact tree (depth 8): methods `vb_{t}` with `Mse` = the
/// estimator's exact variance (exact caches: no bias), and `bound_{t}` with `Mse` = t.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerminationFig4 {
    pub thresholds: Vec<f64>,
}

/// Fig. 5: MSE minimisation on the biased tree (depth 5, bias 0.5 · 0.3^depth): methods
/// `mse_{s}` per target s, `first_vertex` and `path_tracing`, with `Mse` = the exact MSE of the
/// average of `samples` estimates against the root's value.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerminationFig5 {
    pub samples: f64,
    pub targets: Vec<f64>,
}

fn positive(what: &str, v: &[f64]) -> Result<(), String> {
    match v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
        Some(x) => Err(format!("{what} {x}; expected finite numbers > 0")),
        None if v.is_empty() => Err(format!("no {what}; expected at least one")),
        None => Ok(()),
    }
}

fn mse_of(labels: impl Iterator<Item = String>) -> BTreeMap<String, Vec<&'static str>> {
    labels.map(|l| (l, vec!["Mse"])).collect()
}

fn put(out: &mut ComputedValues, label: String, mse: f64) {
    out.entry(label).or_default().insert("Mse", mse);
}

impl Computed for TerminationFig4 {
    fn check(&self) -> Result<(), String> {
        positive("thresholds", &self.thresholds)
    }

    fn methods(&self) -> BTreeMap<String, Vec<&'static str>> {
        mse_of(self.thresholds.iter().flat_map(|t| [format!("vb_{t}"), format!("bound_{t}")]))
    }

    fn compute(&self, _seed: u64) -> ComputedValues {
        let tree = SamplingTree::exact(8, TREE_ALBEDO);
        let mut out = ComputedValues::new();
        for &t in &self.thresholds {
            let rule = TerminationRule::VarianceBounding { t, relative: false };
            put(&mut out, format!("vb_{t}"), tree.estimator(&rule, 1.0).variance());
            put(&mut out, format!("bound_{t}"), t);
        }
        out
    }
}

impl TerminationFig5 {
    fn rules(&self) -> Vec<(String, TerminationRule)> {
        let mut rules: Vec<(String, TerminationRule)> = self
            .targets
            .iter()
            .map(|&s| {
                let rule = TerminationRule::MseMinimisation {
                    s,
                    margin: default_margin(),
                    bias_clamp: default_bias_clamp(),
                };
                (format!("mse_{s}"), rule)
            })
            .collect();
        rules.push(("first_vertex".into(), TerminationRule::FirstVertex));
        rules.push(("path_tracing".into(), TerminationRule::PathTracing));
        rules
    }
}

impl Computed for TerminationFig5 {
    fn check(&self) -> Result<(), String> {
        positive("samples", &[self.samples])?;
        positive("targets", &self.targets)
    }

    fn methods(&self) -> BTreeMap<String, Vec<&'static str>> {
        mse_of(self.rules().into_iter().map(|(l, _)| l))
    }

    fn compute(&self, _seed: u64) -> ComputedValues {
        let tree = SamplingTree::biased(5, TREE_ALBEDO, |d| 0.5 * 0.3f64.powi(d as i32));
        let mut out = ComputedValues::new();
        for (label, rule) in self.rules() {
            put(&mut out, label, tree.mse(tree.estimator(&rule, 1.0), self.samples));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fig. 4's tree: variance bounding meets t below the detach threshold; the values per seed
    /// are exact (no seed dependence); Fig. 5's parameters are checked.
    #[test]
    fn figures_give_the_papers_quantities() {
        let fig4 = TerminationFig4 { thresholds: vec![0.01, 1000.0] };
        let v = fig4.compute(1);
        let mse = |l: &str| v[l]["Mse"];
        assert!((mse("vb_0.01") - 0.01).abs() <= 1e-9 * 0.01);
        assert!(mse("vb_1000") < 1000.0);
        assert_eq!(fig4.compute(2), v);
        assert_eq!(fig4.methods().len(), 4);
        assert!(TerminationFig5 { samples: 10.0, targets: vec![] }.check().is_err());
        let fig5 = TerminationFig5 { samples: 10.0, targets: vec![0.1] };
        assert_eq!(
            fig5.methods().keys().collect::<Vec<_>>(),
            ["first_vertex", "mse_0.1", "path_tracing"]
        );
        assert_eq!(fig5.compute(1).len(), 3);
    }
}
