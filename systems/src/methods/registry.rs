//! The methods a scenario can name: the shipped ones, one line each, and any a program adds with
//! [`register`] before it loads a scenario (a test's method, another crate's). Adding a shipped
//! method: its folder, and its plugin here.

use std::sync::RwLock;

use frame::method::{MethodPlugin, Registered, RegisteredMethod};

/// Every shipped method, in the order `flicker` lists them.
pub static REGISTRY: &[&dyn RegisteredMethod] = &[
    &Registered::<path_tracing::Plugin>::ENTRY,
    &Registered::<nirc::plugin::Plugin>::ENTRY,
    &Registered::<sample_cache::Plugin>::ENTRY,
    &Registered::<taa::Plugin>::ENTRY,
    &Registered::<hash_cache::Plugin>::ENTRY,
    &Registered::<volume::transmittance::Plugin>::ENTRY,
    &Registered::<volume::path::Plugin>::ENTRY,
    &Registered::<termination::Plugin>::ENTRY,
    &Registered::<sss::Plugin>::ENTRY,
];

/// Methods registered at run time, after the shipped ones.
static ADDED: RwLock<Vec<&'static dyn RegisteredMethod>> = RwLock::new(Vec::new());

/// Makes method `P` nameable in scenarios of this process. Refuses a name already taken.
pub fn register<P: MethodPlugin>() -> anyhow::Result<()> {
    if find(P::NAME).is_some() {
        anyhow::bail!("a method named '{}' is already registered", P::NAME);
    }
    // A zero-sized value: leaking its box allocates nothing.
    let entry: &'static Registered<P> = Box::leak(Box::new(Registered::<P>::ENTRY));
    ADDED.write().expect("registry lock").push(entry);
    Ok(())
}

/// The method called `name`.
pub fn find(name: &str) -> Option<&'static dyn RegisteredMethod> {
    REGISTRY
        .iter()
        .copied()
        .find(|m| m.name() == name)
        .or_else(|| ADDED.read().expect("registry lock").iter().copied().find(|m| m.name() == name))
}

/// Every method's name, for error messages.
pub fn names() -> Vec<&'static str> {
    let added = ADDED.read().expect("registry lock");
    REGISTRY.iter().chain(added.iter()).map(|m| m.name()).collect()
}
