#!/usr/bin/env bash
# Regenerates the lavapipe tables of nirc/README.md ("Measured on lavapipe") from runs at HEAD:
# the three shipped light-rotation scenarios and the three failure scenarios, then
# summarise_run.py over each. Usage, from the repository root (release build, idle machine):
#   nirc/scripts/readme_tables.sh OUT_DIR
set -euo pipefail
out=${1:?output folder}
cargo build --release --locked --bin flicker
mkdir -p "$out"
git rev-parse --short HEAD | tee "$out/commit"
for s in light_rotation_courtyard light_rotation_cornell_box light_rotation_corridor nirc_failure_dark nirc_failure_glossy nirc_failure_thin; do
  t0=$(date +%s)
  target/release/flicker run "scenarios/$s.ron" --out "$out/$s" --quiet
  echo "### $s ($(( $(date +%s) - t0 )) s)"
  python3 nirc/scripts/summarise_run.py "$out/$s" 20
done | tee "$out/tables.md"
