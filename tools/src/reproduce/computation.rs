//! Claim cases computed instead of played: the papers' own test cases that are closed forms or
//! Monte Carlo on the CPU. Each is declared by the method whose paper it reproduces
//! (`frame::computation`, e.g. the jackknife's Table 1 in `volume::table1`, the termination
//! paper's sampling trees in `termination::figures`); a claims file writes
//! `computation: NAME(field: value, ...)`, found here through the registry. A computation names
//! its "methods" (rows of the paper's table) and the statistics each records, and yields one
//! value per method and statistic per seed, as a one-frame run, so claims judge them as they
//! judge scenario runs.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use playback::methods::Computed;
use playback::methods::registry;
use serde::de::{self, EnumAccess, MapAccess, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer};

use crate::suite::measurement::{CaseRuns, SeedRun};
use crate::suite::metric::Metric;

/// A claims file's computation: its declared name, its parameters as written, and the method's
/// computation with them read and checked.
#[derive(Clone)]
pub struct Computation {
    name: &'static str,
    params: ron::Value,
    computed: Arc<dyn Computed>,
}

/// The same computation: the same name and parameters.
impl PartialEq for Computation {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name && self.params == other.params
    }
}

impl fmt::Debug for Computation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}({:?})", self.name, self.params)
    }
}

impl Computation {
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// Each method label and the metrics it records; an error names a statistic no method
    /// declares.
    pub fn methods(&self) -> Result<BTreeMap<String, Vec<Metric>>, String> {
        self.computed
            .methods()
            .into_iter()
            .map(|(label, names)| {
                let metrics = names
                    .into_iter()
                    .map(|n| {
                        Metric::named(n)
                            .ok_or_else(|| format!("records {n}, which is no known statistic"))
                    })
                    .collect::<Result<_, _>>()?;
                Ok((label, metrics))
            })
            .collect()
    }

    /// One seed's values, keyed as runs key them (`mse`, `mean_std`).
    fn compute(&self, seed: u64) -> BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>> {
        self.computed
            .compute(seed)
            .into_iter()
            .map(|(label, values)| {
                let values = values
                    .into_iter()
                    .map(|(n, v)| {
                        (Metric::named(n).map_or(n, Metric::name).to_string(), vec![Some(v)])
                    })
                    .collect();
                (label, values)
            })
            .collect()
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

/// `NAME(field: value, ...)`: the name is looked up in the registry, the fields go to the
/// computation that declares it.
impl<'de> Deserialize<'de> for Computation {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_enum("Computation", &[], ComputationVisitor)
    }
}

struct ComputationVisitor;

impl<'de> Visitor<'de> for ComputationVisitor {
    type Value = Computation;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a computation, NAME(field: value, ...)")
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Computation, A::Error> {
        let (FieldName(name), variant): (FieldName, _) = data.variant()?;
        let params = variant.struct_variant(&[], FieldsVisitor)?;
        let declared = registry::computation(&name).ok_or_else(|| {
            de::Error::custom(format!(
                "unknown computation '{name}'; expected one of: {}",
                registry::computation_names().join(", ")
            ))
        })?;
        let computed = (declared.load)(params.clone())
            .map_err(|e| de::Error::custom(format!("{name}: {e}")))?;
        Ok(Computation { name: declared.name, params, computed: Arc::from(computed) })
    }
}

/// A computation's fields as written, for the method's own type to read.
struct FieldsVisitor;

impl<'de> Visitor<'de> for FieldsVisitor {
    type Value = ron::Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "the computation's fields, (field: value, ...)")
    }

    fn visit_map<M: MapAccess<'de>>(self, mut map: M) -> Result<ron::Value, M::Error> {
        let mut fields = ron::Map::new();
        while let Some((FieldName(key), value)) = map.next_entry::<FieldName, ron::Value>()? {
            fields.insert(ron::Value::String(key), value);
        }
        Ok(ron::Value::Map(fields))
    }
}

/// A name in RON: an identifier (a computation's or a field's), not a quoted string.
struct FieldName(String);

impl<'de> Deserialize<'de> for FieldName {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Name;
        impl Visitor<'_> for Name {
            type Value = FieldName;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a field name")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<FieldName, E> {
                Ok(FieldName(v.to_string()))
            }
        }
        deserializer.deserialize_identifier(Name)
    }
}
