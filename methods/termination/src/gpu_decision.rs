//! The termination decision as the cache's passes run it: its WGSL module (shaders/decision.wgsl)
//! and a rule as the shader's words. tests/termination_gpu.rs runs it on a batch of cases
//! against the CPU reference.

use super::rule::TerminationRule;
use render::shader::Module;

/// `package::termination::decision`: the decision, imported by the cache's passes and the
/// GPU-vs-CPU test's probe.
pub fn decision_module() -> Module {
    render::wgsl_file!("decision.wgsl")
}

/// The rule as the shader's `TcRule` fields: (kind, relative, param, margin, bias_clamp).
pub fn rule_words(rule: &TerminationRule) -> (u32, u32, f32, f32, f32) {
    match *rule {
        TerminationRule::VarianceBounding { t, relative } => {
            (0, relative as u32, t as f32, 1.0, 0.0)
        }
        TerminationRule::MseMinimisation { s, margin, bias_clamp } => {
            (1, 0, s as f32, margin as f32, bias_clamp as f32)
        }
        TerminationRule::AreaSpread { c } => (2, 0, c as f32, 1.0, 0.0),
        TerminationRule::FirstVertex => (3, 0, 0.0, 1.0, 0.0),
        TerminationRule::PathTracing => (4, 0, 0.0, 1.0, 0.0),
    }
}
