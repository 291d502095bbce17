//! The jackknife paper's Table 1 (mN = 24) as claims compute it: `m{m}_n{N}` rows with
//! `MeanAbsBias` = |mean − T| and `MeanStd` over `trials` estimates per seed, on normal
//! optical-depth inputs (`JackknifeTable1`, media::jackknife_table's model of σ(N)) or from
//! Algorithm 1's own estimates along the Fig. 4a-like profile (`JackknifeTable1Alg1`,
//! media::table1_alg1).

use std::collections::BTreeMap;

use frame::computation::load;
use frame::method::{Computed, ComputedValues, DeclaredComputation};
use serde::Deserialize;

/// The two forms of Table 1, by the names claims files write.
pub const COMPUTATIONS: &[DeclaredComputation] = &[
    DeclaredComputation { name: "JackknifeTable1", load: load::<JackknifeTable1> },
    DeclaredComputation { name: "JackknifeTable1Alg1", load: load::<JackknifeTable1Alg1> },
];

/// Table 1 on normal optical-depth inputs whose σ(N) follows media::jackknife_table's model.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JackknifeTable1 {
    pub trials: usize,
}

/// Table 1 from Algorithm 1's optical-depth estimates along the Fig. 4a-like profile with
/// per-voxel noise `voxel_noise` (0.9 the claims' profile, 0 the smooth fBm) and super-voxels of
/// `super_voxel` voxels (128: one over the whole ray, Sec. 4.1's stratified sampling; 16: the
/// paper's importance sampling), against the profile's exact T.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JackknifeTable1Alg1 {
    pub trials: usize,
    pub super_voxel: u32,
    pub voxel_noise: f32,
}

fn rows<'a>(rows: impl Iterator<Item = (usize, u32)> + 'a) -> BTreeMap<String, Vec<&'static str>> {
    rows.map(|(m, n)| (format!("m{m}_n{n}"), vec!["MeanAbsBias", "MeanStd"])).collect()
}

fn at_least_two(trials: usize) -> Result<(), String> {
    if trials < 2 { Err(format!("trials {trials}; expected at least 2")) } else { Ok(()) }
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

/// Row (seed, `row`)'s random stream: rows and seeds are independent.
fn stream(seed: u64, row: usize) -> media::Pcg {
    media::Pcg::new(media::rng::image_seed(seed as u32, 0, row as u32, 0))
}

/// Row (m, N)'s |mean − T| and std from the sums of `trials` estimates and their squares.
fn put_row(
    out: &mut ComputedValues,
    m: usize,
    n: u32,
    trials: usize,
    (s1, s2): (f64, f64),
    t: f64,
) {
    let count = trials as f64;
    let mean = s1 / count;
    let var = (s2 / count - mean * mean) * count / (count - 1.0);
    let row = out.entry(format!("m{m}_n{n}")).or_default();
    row.insert("MeanAbsBias", (mean - t).abs());
    row.insert("MeanStd", var.max(0.0).sqrt());
}

impl Computed for JackknifeTable1 {
    fn check(&self) -> Result<(), String> {
        at_least_two(self.trials)
    }

    fn methods(&self) -> BTreeMap<String, Vec<&'static str>> {
        rows(media::jackknife_table::TABLE_1.iter().map(|&(m, n, ..)| (m, n)))
    }

    fn compute(&self, seed: u64) -> ComputedValues {
        use media::jackknife_table::{T, TABLE_1, trial};
        let sums = row_sums(&TABLE_1, |row, &(m, n, ..)| {
            let mut rng = stream(seed, row);
            let mut x = [0.0; 8];
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..self.trials {
                let k = trial(m, n, &mut rng, &mut x);
                s1 += k;
                s2 += k * k;
            }
            (s1, s2)
        });
        let mut out = ComputedValues::new();
        for (&(m, n, ..), sums) in TABLE_1.iter().zip(sums) {
            put_row(&mut out, m, n, self.trials, sums, T);
        }
        out
    }
}

impl Computed for JackknifeTable1Alg1 {
    fn check(&self) -> Result<(), String> {
        use media::table1_alg1::PROFILE_VOXELS;
        at_least_two(self.trials)?;
        if !(0.0..=1.0).contains(&self.voxel_noise) {
            return Err(format!(
                "voxel_noise {}; expected 0 to 1 (extinction stays >= 0)",
                self.voxel_noise
            ));
        }
        if !(1..=PROFILE_VOXELS).contains(&self.super_voxel) {
            return Err(format!(
                "super_voxel {}; expected 1 to {PROFILE_VOXELS} (the profile's voxels)",
                self.super_voxel
            ));
        }
        Ok(())
    }

    fn methods(&self) -> BTreeMap<String, Vec<&'static str>> {
        rows(media::table1_alg1::ROWS.iter().copied())
    }

    fn compute(&self, seed: u64) -> ComputedValues {
        use media::table1_alg1::{ROWS, Table1Profile};
        let profile = Table1Profile::new(self.super_voxel, self.voxel_noise);
        let sums = row_sums(&ROWS, |row, &(m, n)| {
            let mut rng = stream(seed, row);
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..self.trials {
                let k = profile.trial(m, n, &mut rng);
                s1 += k;
                s2 += k * k;
            }
            (s1, s2)
        });
        let mut out = ComputedValues::new();
        for (&(m, n), sums) in ROWS.iter().zip(sums) {
            put_row(&mut out, m, n, self.trials, sums, profile.transmittance());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same numbers for the same seed; Table 1's naive row carries its Jensen bias, Eq. 3's
    /// m = 2 not, on normal inputs and from Algorithm 1 (SE of a row's mean about 0.0003).
    #[test]
    fn table_1_gives_the_papers_quantities() {
        let table = JackknifeTable1 { trials: 20_000 }.compute(3);
        let bias = |l: &str| table[l]["MeanAbsBias"];
        // SE of the m = 2 mean: 0.0405 / sqrt(20000) ≈ 0.00029; the naive bias is 0.00386.
        assert!(bias("m2_n12") < 5.0 * 0.00029, "{}", bias("m2_n12"));
        assert!((bias("m1_n24") - 0.00386).abs() < 5.0 * 0.00029, "{}", bias("m1_n24"));
        assert!(JackknifeTable1 { trials: 1 }.check().is_err());
        let alg1 = JackknifeTable1Alg1 { trials: 20_000, super_voxel: 128, voxel_noise: 0.9 };
        let rows = alg1.compute(5);
        assert_eq!(alg1.compute(5), rows);
        assert_eq!(alg1.methods().len(), 6);
        let bias = |l: &str| rows[l]["MeanAbsBias"];
        assert!(bias("m1_n24") > bias("m2_n12") + 5.0 * 0.00035, "{rows:?}");
        let bad =
            |super_voxel, voxel_noise| JackknifeTable1Alg1 { trials: 10, super_voxel, voxel_noise };
        assert!(bad(0, 0.9).check().is_err() && bad(129, 0.9).check().is_err());
        assert!(bad(16, 1.5).check().is_err() && bad(16, 0.0).check().is_ok());
    }

    /// Rows on threads of their own give the bits of rows one after another.
    #[test]
    fn rows_on_threads_give_the_serial_bits() {
        use media::table1_alg1::{ROWS, Table1Profile};
        let (trials, seed) = (2_000, 7u64);
        let profile = Table1Profile::new(16, 0.9);
        let mut serial = ComputedValues::new();
        for (row, &(m, n)) in ROWS.iter().enumerate() {
            let mut rng = stream(seed, row);
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..trials {
                let k = profile.trial(m, n, &mut rng);
                s1 += k;
                s2 += k * k;
            }
            put_row(&mut serial, m, n, trials, (s1, s2), profile.transmittance());
        }
        let threaded =
            JackknifeTable1Alg1 { trials, super_voxel: 16, voxel_noise: 0.9 }.compute(seed);
        assert_eq!(format!("{threaded:?}"), format!("{serial:?}"));
    }
}
