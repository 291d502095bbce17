#!/usr/bin/env bash
# The paper-scale part of a GPU session (after scripts/device_check.sh): each paper's scenarios at
# a size a GPU plays in seconds, with the release binary built at the commit being measured.
# Usage, on the device machine, from the repository root:
#   scripts/device_papers.sh target/release/flicker OUT_DIR [SECONDS_FOR_REPRODUCE [TOTAL_SECONDS]]
# Each step has its own time limit, and none starts past TOTAL_SECONDS (default 420) so that the
# tarball is always written.
# Writes OUT_DIR/papers.tar.gz (every run's summary.json, frames.csv and manifest.json, the
# benches' JSON, the reproduce report) and prints each step's exit status and wall time.
set -uo pipefail
bin=${1:?flicker binary}; out=${2:?output folder}; reproduce_s=${3:-150}; total_s=${4:-420}
start=$(date +%s)
mkdir -p "$out"
work=$(mktemp -d)
export FLICKER_CACHE_DIR=$work/cache
step() {
  local name=$1 limit=$2; shift 2
  local left=$((total_s - ($(date +%s) - start)))
  if [ "$left" -le 5 ]; then echo "$name: skipped (past the total of $total_s s)"; return; fi
  [ "$limit" -gt "$left" ] && limit=$left
  local t0=$(date +%s.%N)
  timeout "$limit" "$@" >"$work/$name.log" 2>&1; local rc=$?
  local t1=$(date +%s.%N)
  printf '%s: exit %d, %.1f s\n' "$name" "$rc" "$(awk "BEGIN{print $t1 - $t0}")"
  tail -n 2 "$work/$name.log"
}
run() { # name limit scenario [flags]
  local name=$1 limit=$2 scenario=$3; shift 3
  step "$name" "$limit" "$bin" run "$scenario" --quiet --out "$work/runs/$name" "$@"
}
step bench_nirc 120 "$bin" bench --nirc --json "$work/bench_nirc.json"
step bench_memory 60 "$bin" bench --memory --json "$work/bench_memory.json"
# Variance-trading termination (the paper's Table 1 scenes) and the jackknife's media at 320x180.
for s in termination_door_gap termination_corridor volume_cloud volume_explosion \
  volume_explosion_supervoxel volume_mis volume_mis_exact volume_shadow volume_moving_light \
  volume_mesh_bound; do
  run "$s" 60 "scenarios/$s.ron" --resolution 320x180
done
# Screen-space SSS (the thesis's Table 7.3 tests) at 1280x720.
for s in sss_flash sss_toggle sss_boids sss_moving; do
  run "$s" 90 "scenarios/$s.ron" --resolution 1280x720
done
# The stable sample cache at the paper's 1920x1080 (figure 7's strategies, adaptive shading).
for s in hairball_camera adaptive_shading_cache glossy_cache; do
  run "$s" 90 "scenarios/$s.ron" --resolution 1920x1080
done
step reproduce "$reproduce_s" "$bin" reproduce all --scale paper --out "$work/reproduce"
(cd "$work" && find . -name summary.json -o -name frames.csv -o -name manifest.json \
  -o -name '*.log' -o -name 'bench_*.json' -o -name 'reproduce.md' | grep -v '^./cache' \
  | tar czf "$out/papers.tar.gz" -T -)
ls -la "$out"
