#!/usr/bin/env bash
# The NIRC light-rotation experiment at the paper's scale (scenarios/paper/, for a GPU): for each
# scene, every seed (the seeds run side by side), then nirc/scripts/seeds_summary.py over the
# runs. Usage, from the repository root:
#   [SCENES="cornell_box courtyard corridor"] nirc/scripts/paper_experiment.sh FLICKER OUT_DIR [SEED ...]
# (default seeds 1 2 3 4 5). OUT_DIR/runs.tar collects each finished run's frames.csv and
# summary.json as it goes; OUT_DIR/summary.md gets the tables.
set -uo pipefail
bin=${1:?flicker binary}; out=${2:?output folder}; shift 2
seeds=("$@"); [ ${#seeds[@]} -eq 0 ] && seeds=(1 2 3 4 5)
mkdir -p "$out/runs"
export FLICKER_CACHE_DIR=${FLICKER_CACHE_DIR:-$out/cache}
for scene in ${SCENES:-cornell_box courtyard corridor}; do
  t0=$(date +%s)
  for seed in "${seeds[@]}"; do
    (
      run="$out/runs/$scene-seed$seed"
      "$bin" run "scenarios/paper/nirc_light_rotation_$scene.ron" --seed "$seed" --out "$run" --quiet >"$run.log" 2>&1
      echo "$scene seed $seed: exit $? at $(( $(date +%s) - t0 )) s"
    ) &
  done
  wait
  (cd "$out/runs" && tar rf ../runs.tar ./*/frames.csv ./*/summary.json 2>/dev/null; true)
done
python3 nirc/scripts/seeds_summary.py "$out/runs" 20 | tee "$out/summary.md"
