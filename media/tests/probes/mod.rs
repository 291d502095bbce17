//! GPU probes of the media library, for the tests only: passes that run the library's WGSL on
//! given inputs so that a test can compare it with the CPU twin of the same math, and those
//! twins where the library itself has no use for them (the closed-form settings of the paper's
//! Sec. 3 and of Eqs. 9/10).
//!
//! - `estimator_pass` (rays.wgsl): one estimator on a list of segments, each with its seed;
//! - `closed_form` and `closed_form_pass` (closed_form_trials.wgsl): Figs. 2 and 3's setting;
//! - `mis_trial` and `mis_pass` (mis_trials.wgsl): Eqs. 9/10's setting;
//! - `trials`: what the two trial passes share.
// Each test binary uses some of these.
#![allow(dead_code)]

pub mod closed_form;
pub mod closed_form_pass;
pub mod estimator_pass;
pub mod mis_pass;
pub mod mis_trial;
mod trials;

use render::shader::Module;

/// A probe's entry-point file, named like the library's modules (`package::media::NAME`).
fn module(name: &str, source: &'static str) -> Module {
    Module {
        path: format!("package::media::{name}").into(),
        file: format!("media/tests/probes/{name}.wgsl").into(),
        source: source.into(),
    }
}
