//! Claim cases computed instead of played: a paper's own test case that is a closed form or
//! Monte Carlo on the CPU (the jackknife's Table 1, the termination paper's sampling trees). The
//! method whose paper it reproduces declares it (`MethodPlugin::COMPUTATIONS`); a claims file
//! names it, `computation: NAME(field: value, ...)`, and `flicker reproduce` finds it through
//! the registry and judges its values as it judges a one-frame run's, so the crates that read
//! claims need no method crate.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::DeserializeOwned;

/// One seed's values: per method label (a row of the paper's table), per statistic as claims
/// name it (`Mse`, `MeanStd`), the value.
pub type ComputedValues = BTreeMap<String, BTreeMap<&'static str, f64>>;

/// A computation with its parameters read: what it records and its values per seed.
pub trait Computed: Send + Sync + fmt::Debug {
    /// What is wrong with the parameters, if anything (checked when a claims file loads).
    fn check(&self) -> Result<(), String> {
        Ok(())
    }
    /// Each method label and the statistics (claims' names) it records.
    fn methods(&self) -> BTreeMap<String, Vec<&'static str>>;
    /// One seed's values; the same seed gives the same bits.
    fn compute(&self, seed: u64) -> ComputedValues;
}

/// A computation a method declares: the name claims files write and how its parameters load.
#[derive(Clone, Copy)]
pub struct DeclaredComputation {
    pub name: &'static str,
    /// Reads the parameters (the fields the claims file writes, as a RON map) and checks them.
    pub load: fn(ron::Value) -> Result<Box<dyn Computed>, String>,
}

impl fmt::Debug for DeclaredComputation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DeclaredComputation").field("name", &self.name).finish()
    }
}

/// [`DeclaredComputation::load`] for a computation whose parameters are a serde struct.
pub fn load<T: DeserializeOwned + Computed + 'static>(
    params: ron::Value,
) -> Result<Box<dyn Computed>, String> {
    let computed: T = params.into_rust().map_err(|e| e.to_string())?;
    computed.check()?;
    Ok(Box::new(computed))
}
