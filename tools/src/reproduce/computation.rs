//! Claim cases computed here instead of played as scenarios: the papers' own test cases that
//! are closed forms or Monte Carlo on the CPU (the jackknife's Table 1 from Algorithm 1 along a
//! Fig. 4a-like profile and on normal inputs, the termination paper's sampling trees of Figs. 4
//! and 5). A computation names its "methods" (rows of the paper's table) and the metrics each
//! records, and yields one value per method and metric per seed, as a one-frame run, so claims
//! judge them as they judge scenario runs.

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::suite::measurement::{CaseRuns, SeedRun};
use crate::suite::metric::Metric;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Computation {
    /// jackknife-transmittance Table 1 (mN = 24) on normal optical-depth inputs
    /// (media::jackknife_table's model of σ(N)): methods `m{m}_n{N}` (m = 1: the naive
    /// exp(−X)), `MeanAbsBias` = |mean − T| and `MeanStd` over `trials` trials per seed.
    JackknifeTable1 { trials: usize },
    /// jackknife-transmittance Table 1 (mN = 24) from Algorithm 1's own optical-depth
    /// estimates along the Fig. 4a-like profile (media::table1_alg1) with per-voxel noise
    /// `voxel_noise` (0.9 the claims' profile, 0 the smooth fBm), super-voxels of `super_voxel`
    /// voxels (128: one over the whole ray, Sec. 4.1's stratified sampling; 16: the paper's
    /// importance sampling): methods `m{m}_n{N}` with `MeanAbsBias` = |mean − T| against the
    /// profile's exact T and `MeanStd`, over `trials` trials per seed.
    JackknifeTable1Alg1 { trials: usize, super_voxel: u32, voxel_noise: f32 },
    /// variance-trading-termination Fig. 4: variance bounding on the exact sampling tree
    /// (depth 8, albedo 0.9, left child 90%): methods `vb_{t}` with `Mse` = the estimator's
    /// exact variance (exact caches: no bias), and `bound_{t}` with `Mse` = t.
    TerminationFig4 { thresholds: Vec<f64> },
    /// variance-trading-termination Fig. 5: MSE minimisation on the biased tree (depth 5, bias
    /// 0.5 · 0.3^depth): methods `mse_{s}` per target s, `first_vertex` and `path_tracing`, with
    /// `Mse` = the exact MSE of the average of `samples` estimates against the root's value.
    TerminationFig5 { samples: f64, targets: Vec<f64> },
}

type Values = BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>>;

const TREE_ALBEDO: f64 = 0.9;

fn put(out: &mut Values, method: String, metric: Metric, v: f64) {
    out.entry(method).or_default().insert(metric.name().to_string(), vec![Some(v)]);
}

/// Each row's sums (Σk, Σk²) on a thread of its own: a row draws from its own stream and adds in
/// its own order, so the sums are the same bits as rows one after another, sooner on many cores.
fn row_sums<R: Sync>(rows: &[R], sums: impl Fn(usize, &R) -> (f64, f64) + Sync) -> Vec<(f64, f64)> {
    let sums = &sums;
    std::thread::scope(|s| {
        let rows: Vec<_> =
            rows.iter().enumerate().map(|(i, r)| s.spawn(move || sums(i, r))).collect();
        rows.into_iter().map(|r| r.join().expect("a row's trials")).collect()
    })
}

/// Row (m, N)'s |mean − T| and std from the sums of `trials` estimates and their squares.
fn put_row(out: &mut Values, m: usize, n: u32, trials: usize, s1: f64, s2: f64, t: f64) {
    let count = trials as f64;
    let mean = s1 / count;
    let var = (s2 / count - mean * mean) * count / (count - 1.0);
    let label = format!("m{m}_n{n}");
    put(out, label.clone(), Metric::shipped("MeanAbsBias"), (mean - t).abs());
    put(out, label, Metric::shipped("MeanStd"), var.max(0.0).sqrt());
}

impl Computation {
    pub fn name(&self) -> &'static str {
        match self {
            Computation::JackknifeTable1 { .. } => "JackknifeTable1",
            Computation::JackknifeTable1Alg1 { .. } => "JackknifeTable1Alg1",
            Computation::TerminationFig4 { .. } => "TerminationFig4",
            Computation::TerminationFig5 { .. } => "TerminationFig5",
        }
    }

    /// Each method label and the metrics it records.
    pub fn methods(&self) -> BTreeMap<String, Vec<Metric>> {
        match self {
            Computation::JackknifeTable1 { .. } => media::jackknife_table::TABLE_1
                .iter()
                .map(|&(m, n, ..)| {
                    (
                        format!("m{m}_n{n}"),
                        vec![Metric::shipped("MeanAbsBias"), Metric::shipped("MeanStd")],
                    )
                })
                .collect(),
            Computation::JackknifeTable1Alg1 { .. } => media::table1_alg1::ROWS
                .iter()
                .map(|&(m, n)| {
                    (
                        format!("m{m}_n{n}"),
                        vec![Metric::shipped("MeanAbsBias"), Metric::shipped("MeanStd")],
                    )
                })
                .collect(),
            Computation::TerminationFig4 { thresholds } => thresholds
                .iter()
                .flat_map(|t| [format!("vb_{t}"), format!("bound_{t}")])
                .map(|l| (l, vec![Metric::Mse]))
                .collect(),
            Computation::TerminationFig5 { targets, .. } => targets
                .iter()
                .map(|s| format!("mse_{s}"))
                .chain(["first_vertex".to_string(), "path_tracing".to_string()])
                .map(|l| (l, vec![Metric::Mse]))
                .collect(),
        }
    }

    /// What is wrong with the parameters, if anything.
    pub fn check(&self) -> Result<(), String> {
        let positive =
            |what: &str, v: &[f64]| match v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                Some(x) => Err(format!("{what} {x}; expected finite numbers > 0")),
                None if v.is_empty() => Err(format!("no {what}; expected at least one")),
                None => Ok(()),
            };
        match self {
            Computation::JackknifeTable1 { trials } if *trials < 2 => {
                Err(format!("trials {trials}; expected at least 2"))
            }
            Computation::JackknifeTable1 { .. } => Ok(()),
            Computation::JackknifeTable1Alg1 { trials, .. } if *trials < 2 => {
                Err(format!("trials {trials}; expected at least 2"))
            }
            Computation::JackknifeTable1Alg1 { voxel_noise, .. }
                if !(0.0..=1.0).contains(voxel_noise) =>
            {
                Err(format!("voxel_noise {voxel_noise}; expected 0 to 1 (extinction stays >= 0)"))
            }
            Computation::JackknifeTable1Alg1 { super_voxel, .. }
                if !(1..=media::table1_alg1::PROFILE_VOXELS).contains(super_voxel) =>
            {
                Err(format!(
                    "super_voxel {super_voxel}; expected 1 to {} (the profile's voxels)",
                    media::table1_alg1::PROFILE_VOXELS
                ))
            }
            Computation::JackknifeTable1Alg1 { .. } => Ok(()),
            Computation::TerminationFig4 { thresholds } => positive("thresholds", thresholds),
            Computation::TerminationFig5 { samples, targets } => {
                positive("samples", &[*samples])?;
                positive("targets", targets)
            }
        }
    }

    /// One seed's values.
    pub fn compute(&self, seed: u64) -> Values {
        let mut out = Values::new();
        match self {
            Computation::JackknifeTable1 { trials } => {
                use media::jackknife_table::{T, TABLE_1, trial};
                let sums = row_sums(&TABLE_1, |row, &(m, n, ..)| {
                    // A stream per (seed, row): rows and seeds are independent.
                    let mut rng =
                        media::Pcg::new(media::rng::image_seed(seed as u32, 0, row as u32, 0));
                    let mut x = [0.0; 8];
                    let (mut s1, mut s2) = (0.0f64, 0.0f64);
                    for _ in 0..*trials {
                        let k = trial(m, n, &mut rng, &mut x);
                        s1 += k;
                        s2 += k * k;
                    }
                    (s1, s2)
                });
                for (&(m, n, ..), (s1, s2)) in TABLE_1.iter().zip(sums) {
                    put_row(&mut out, m, n, *trials, s1, s2, T);
                }
            }
            Computation::JackknifeTable1Alg1 { trials, super_voxel, voxel_noise } => {
                use media::table1_alg1::{ROWS, Table1Profile};
                let profile = Table1Profile::new(*super_voxel, *voxel_noise);
                let t = profile.transmittance();
                let sums = row_sums(&ROWS, |row, &(m, n)| {
                    let mut rng =
                        media::Pcg::new(media::rng::image_seed(seed as u32, 0, row as u32, 0));
                    let (mut s1, mut s2) = (0.0f64, 0.0f64);
                    for _ in 0..*trials {
                        let k = profile.trial(m, n, &mut rng);
                        s1 += k;
                        s2 += k * k;
                    }
                    (s1, s2)
                });
                for (&(m, n), (s1, s2)) in ROWS.iter().zip(sums) {
                    put_row(&mut out, m, n, *trials, s1, s2, t);
                }
            }
            Computation::TerminationFig4 { thresholds } => {
                let tree = termination::SamplingTree::exact(8, TREE_ALBEDO);
                for &t in thresholds {
                    let rule =
                        termination::TerminationRule::VarianceBounding { t, relative: false };
                    put(
                        &mut out,
                        format!("vb_{t}"),
                        Metric::Mse,
                        tree.estimator(&rule, 1.0).variance(),
                    );
                    put(&mut out, format!("bound_{t}"), Metric::Mse, t);
                }
            }
            Computation::TerminationFig5 { samples, targets } => {
                use termination::TerminationRule;
                let tree = termination::SamplingTree::biased(5, TREE_ALBEDO, |d| {
                    0.5 * 0.3f64.powi(d as i32)
                });
                let mut rules: Vec<(String, TerminationRule)> = targets
                    .iter()
                    .map(|&s| {
                        let rule = TerminationRule::MseMinimisation {
                            s,
                            margin: termination::rule::default_margin(),
                            bias_clamp: termination::rule::default_bias_clamp(),
                        };
                        (format!("mse_{s}"), rule)
                    })
                    .collect();
                rules.push(("first_vertex".into(), TerminationRule::FirstVertex));
                rules.push(("path_tracing".into(), TerminationRule::PathTracing));
                for (label, rule) in rules {
                    let mse = tree.mse(tree.estimator(&rule, 1.0), *samples);
                    put(&mut out, label, Metric::Mse, mse);
                }
            }
        }
        out
    }

    /// Every seed, as a case's runs (one frame, no events).
    pub fn runs(&self, seeds: &[u64]) -> CaseRuns {
        let seeds = seeds
            .iter()
            .map(|&seed| SeedRun {
                seed,
                methods: self.compute(seed),
                jod: BTreeMap::new(),
                folder: None,
            })
            .collect();
        CaseRuns { frames: 1, events: Vec::new(), seeds }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fig. 4's tree: variance bounding meets t below the detach threshold; the values per seed
    /// are exact (no seed dependence); Table 1's naive row carries its bias, Eq. 3's m = 2 not.
    #[test]
    fn computations_give_the_papers_quantities() {
        let fig4 = Computation::TerminationFig4 { thresholds: vec![0.01, 1000.0] };
        let v = fig4.compute(1);
        let mse = |l: &str| v[l]["mse"][0].unwrap();
        assert!((mse("vb_0.01") - 0.01).abs() <= 1e-9 * 0.01);
        assert!(mse("vb_1000") < 1000.0);
        assert_eq!(fig4.compute(2), v);
        assert_eq!(fig4.methods().len(), 4);
        let table = Computation::JackknifeTable1 { trials: 20_000 }.compute(3);
        let bias = |l: &str| table[l]["mean_abs_bias"][0].unwrap();
        // SE of the m = 2 mean: 0.0405 / sqrt(20000) ≈ 0.00029; the naive bias is 0.00386.
        assert!(bias("m2_n12") < 5.0 * 0.00029, "{}", bias("m2_n12"));
        assert!((bias("m1_n24") - 0.00386).abs() < 5.0 * 0.00029, "{}", bias("m1_n24"));
        assert!(Computation::TerminationFig5 { samples: 10.0, targets: vec![] }.check().is_err());
        assert!(Computation::JackknifeTable1 { trials: 1 }.check().is_err());
        // Table 1 from Alg. 1: the same numbers for the same seed, and the naive row's Jensen
        // bias (about 0.0034 on this profile) far above the jackknife's (SE ≈ 0.00025 each).
        let alg1 =
            Computation::JackknifeTable1Alg1 { trials: 20_000, super_voxel: 128, voxel_noise: 0.9 };
        let rows = alg1.compute(5);
        assert_eq!(alg1.compute(5), rows);
        assert_eq!(alg1.methods().len(), 6);
        let bias = |l: &str| rows[l]["mean_abs_bias"][0].unwrap();
        assert!(bias("m1_n24") > bias("m2_n12") + 5.0 * 0.00035, "{rows:?}");
        let bad = |super_voxel, voxel_noise| Computation::JackknifeTable1Alg1 {
            trials: 10,
            super_voxel,
            voxel_noise,
        };
        assert!(bad(0, 0.9).check().is_err() && bad(129, 0.9).check().is_err());
        assert!(bad(16, 1.5).check().is_err() && bad(16, 0.0).check().is_ok());
    }

    /// Rows on threads of their own give the bits of rows one after another.
    #[test]
    fn rows_on_threads_give_the_serial_bits() {
        use media::table1_alg1::{ROWS, Table1Profile};
        let (trials, seed) = (2_000, 7u64);
        let profile = Table1Profile::new(16, 0.9);
        let mut serial = Values::new();
        for (row, &(m, n)) in ROWS.iter().enumerate() {
            let mut rng = media::Pcg::new(media::rng::image_seed(seed as u32, 0, row as u32, 0));
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..trials {
                let k = profile.trial(m, n, &mut rng);
                s1 += k;
                s2 += k * k;
            }
            put_row(&mut serial, m, n, trials, s1, s2, profile.transmittance());
        }
        let threaded =
            Computation::JackknifeTable1Alg1 { trials, super_voxel: 16, voxel_noise: 0.9 }
                .compute(seed);
        assert_eq!(format!("{threaded:?}"), format!("{serial:?}"));
    }
}
