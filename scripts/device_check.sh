#!/usr/bin/env bash
# The GPU check a session runs when it is lent an NVIDIA machine (see the developers' guide):
# `flicker bench`, one light-rotation and one hairball scenario and `flicker reproduce all --scale
# lab`, with the release binary built at the commit being measured. Usage, on the device
# machine, from the repository root:
#   scripts/device_check.sh target/release/flicker OUT_DIR
# Prints a Markdown block for docs/gpu.md (wall time of each step) and copies the runs'
# summary.json and frames.csv to OUT_DIR.
set -uo pipefail
bin=${1:?flicker binary}; out=${2:?output folder}
mkdir -p "$out"
export FLICKER_CACHE_DIR=$(mktemp -d)
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || true
step() {
  local name=$1; shift
  local t0=$(date +%s.%N)
  "$@" >"$out/$name.log" 2>&1; local rc=$?
  local t1=$(date +%s.%N)
  printf '%s: exit %d, %.1f s\n' "$name" "$rc" "$(awk "BEGIN{print $t1 - $t0}")"
  tail -n 3 "$out/$name.log"
}
step bench "$bin" bench --no-metrics --out "$out/bench.md"
cat "$out/bench.md"
step light_rotation "$bin" run scenarios/light_rotation_cornell_box.ron --out /tmp/runs/light_rotation
step hairball "$bin" run scenarios/hairball.ron --out /tmp/runs/hairball
# The papers' claims at lab scale (docs/reproduce.md).
step reproduce_lab "$bin" reproduce all --scale lab --out /tmp/runs/reproduce_lab --quiet
cp /tmp/runs/reproduce_lab/reproduce.md "$out/reproduce_lab.md" 2>/dev/null
for r in light_rotation hairball; do
  cp /tmp/runs/$r/summary.json "$out/$r.summary.json" 2>/dev/null
  cp /tmp/runs/$r/frames.csv "$out/$r.frames.csv" 2>/dev/null
done
grep -h "adapter" /tmp/runs/*/manifest.json | head -2
