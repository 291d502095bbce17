//! The methods a scenario can name: the shipped ones, one line each in [`visit_shipped`], and any
//! a program adds with [`register`] before it loads a scenario (a test's method, another
//! crate's). Adding a shipped method: its folder under `methods/`, and its line here. What a
//! method records (its statistics and charts) comes with its plugin: [`statistic`] finds one by
//! name, [`charts`] lists them all.

use std::sync::{LazyLock, RwLock};

use frame::method::{
    DeclaredComputation, MethodChart, MethodPlugin, Registered, RegisteredMethod, Statistic,
};

/// Something done once per plugin type (the registry's entries; the documentation test reads
/// each method's settings type).
pub trait PluginVisitor {
    fn visit<P: MethodPlugin>(&mut self);
}

/// Every shipped method, in the order `flicker` lists them: one line per method.
pub fn visit_shipped(v: &mut impl PluginVisitor) {
    v.visit::<path_tracing::Plugin>();
    v.visit::<nirc::plugin::Plugin>();
    v.visit::<sample_cache::Plugin>();
    v.visit::<taa::Plugin>();
    v.visit::<hash_cache::Plugin>();
    v.visit::<volume::transmittance::Plugin>();
    v.visit::<volume::path::Plugin>();
    v.visit::<termination::Plugin>();
    v.visit::<sss::Plugin>();
}

/// The registry's entry of plugin `P`; a zero-sized value, so leaking its box allocates nothing.
fn entry<P: MethodPlugin>() -> &'static dyn RegisteredMethod {
    Box::leak(Box::new(Registered::<P>::ENTRY))
}

/// The shipped methods' entries.
fn shipped() -> &'static [&'static dyn RegisteredMethod] {
    struct Entries(Vec<&'static dyn RegisteredMethod>);
    impl PluginVisitor for Entries {
        fn visit<P: MethodPlugin>(&mut self) {
            self.0.push(entry::<P>());
        }
    }
    static SHIPPED: LazyLock<Vec<&'static dyn RegisteredMethod>> = LazyLock::new(|| {
        let mut entries = Entries(Vec::new());
        visit_shipped(&mut entries);
        entries.0
    });
    &SHIPPED
}

/// Methods registered at run time, after the shipped ones.
static ADDED: RwLock<Vec<&'static dyn RegisteredMethod>> = RwLock::new(Vec::new());

/// Every registered method, shipped then added.
pub fn all() -> Vec<&'static dyn RegisteredMethod> {
    let added = ADDED.read().expect("registry lock");
    shipped().iter().chain(added.iter()).copied().collect()
}

/// Makes method `P` nameable in scenarios of this process. Refuses a name already taken, and a
/// statistic whose name or column another method's statistic has.
pub fn register<P: MethodPlugin>() -> anyhow::Result<()> {
    if find(P::NAME).is_some() {
        anyhow::bail!("a method named '{}' is already registered", P::NAME);
    }
    if let Some(c) = P::COMPUTATIONS.iter().find(|c| computation(c.name).is_some()) {
        anyhow::bail!("method '{}': its computation {} is also another method's", P::NAME, c.name);
    }
    for s in P::STATISTICS {
        if let Some((other, _)) = all().into_iter().find_map(|m| {
            m.statistics().iter().find(|t| t.name == s.name || t.column == s.column).map(|t| (m, t))
        }) {
            anyhow::bail!(
                "method '{}': its statistic {} ({}) is also {}'s",
                P::NAME,
                s.name,
                s.column,
                other.name()
            );
        }
    }
    ADDED.write().expect("registry lock").push(entry::<P>());
    Ok(())
}

/// The method called `name`.
pub fn find(name: &str) -> Option<&'static dyn RegisteredMethod> {
    all().into_iter().find(|m| m.name() == name)
}

/// Every method's name, for error messages.
pub fn names() -> Vec<&'static str> {
    all().into_iter().map(|m| m.name()).collect()
}

/// The statistic a claim or a suite calls `name` (`PathLength`), with the method that records it.
pub fn statistic(name: &str) -> Option<(&'static dyn RegisteredMethod, &'static Statistic)> {
    all().into_iter().find_map(|m| m.statistics().iter().find(|s| s.name == name).map(|s| (m, s)))
}

/// Every registered method's statistics, in registry order.
pub fn statistics() -> Vec<&'static Statistic> {
    all().into_iter().flat_map(|m| m.statistics()).collect()
}

/// The computation a claims file calls `name` (`TerminationFig4`), declared by a method.
pub fn computation(name: &str) -> Option<&'static DeclaredComputation> {
    all().into_iter().find_map(|m| m.computations().iter().find(|c| c.name == name))
}

/// Every registered method's computations' names, for error messages.
pub fn computation_names() -> Vec<&'static str> {
    all().into_iter().flat_map(|m| m.computations().iter().map(|c| c.name)).collect()
}

/// Every registered method's charts, in registry order: what the report draws where a run has
/// their columns.
pub fn charts() -> Vec<MethodChart> {
    all().into_iter().flat_map(|m| m.charts().iter().copied()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn computations_are_found_by_name_with_distinct_names() {
        assert!(
            computation("TerminationFig4").is_some()
                && computation("JackknifeTable1Alg1").is_some()
        );
        assert!(computation("Flip").is_none() && computation("Termination").is_none());
        let mut names = computation_names();
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!((names.len(), count), (4, 4), "{names:?}");
    }

    #[test]
    fn statistics_are_found_by_name_with_their_method() {
        let (method, s) = statistic("PathLength").expect("termination's statistic");
        assert_eq!((method.name(), s.column), ("Termination", "path_length"));
        assert_eq!(statistic("SssPsnr").map(|(m, _)| m.name()), Some("Sss"));
        assert!(statistic("Flip").is_none(), "FLIP is every method's, not a method's statistic");
        // Names and columns are distinct over the registry: they key claims and run columns.
        let all = statistics();
        for (i, s) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|t| t.name != s.name && t.column != s.column),
                "{} twice",
                s.name
            );
        }
        assert!(charts().iter().any(|c| c.stem() == "frames_sigma"));
    }
}
