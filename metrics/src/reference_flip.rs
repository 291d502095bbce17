//! NVIDIA's reference FLIP (`flip` from the `flip-evaluator` Python package) run as a
//! subprocess on two files: what our FLIP is checked against (tests/flip_vs_reference.rs) and
//! timed against (the image-metric bench).

use std::process::Command;

use anyhow::Context;

/// NVIDIA's FLIP command-line tool, run through the Python module (no reliance on PATH entry points).
pub fn reference_flip_command() -> Command {
    let mut c = Command::new(crate::python::interpreter());
    c.args(["-m", "flip_evaluator.flip_python_api"]);
    c
}

/// Whether NVIDIA's reference FLIP is installed.
pub fn reference_flip_available() -> bool {
    reference_flip_command().arg("-h").output().is_ok_and(|o| o.status.success())
}

/// Runs NVIDIA's `flip` tool on two EXR files; returns (its evaluation time in ms, mean FLIP).
pub fn run_reference_flip(
    reference: &std::path::Path,
    test: &std::path::Path,
    ppd: f32,
) -> anyhow::Result<(f64, f64)> {
    let out = reference_flip_command()
        .args(["-r".as_ref(), reference.as_os_str(), "-t".as_ref(), test.as_os_str()])
        .args(["-ppd", &ppd.to_string(), "-nerm", "-nexm", "-v", "2"])
        .output()
        .context(
            "cannot run python3 -m flip_evaluator.flip_python_api (scripts/setup-tests.sh installs it)",
        )?;
    let text = String::from_utf8_lossy(&out.stdout);
    anyhow::ensure!(
        out.status.success(),
        "`flip` failed: {}{}",
        text,
        String::from_utf8_lossy(&out.stderr)
    );
    let number_after = |key: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.contains(key))?;
        line.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
            .filter_map(|s| s.parse().ok())
            .next_back()
    };
    let mean = number_after("Mean:").context(format!("no 'Mean:' in flip's output:\n{text}"))?;
    let seconds = number_after("Evaluation time:")
        .context(format!("no 'Evaluation time:' in flip's output:\n{text}"))?;
    Ok((seconds * 1e3, mean))
}
