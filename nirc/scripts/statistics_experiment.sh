#!/usr/bin/env bash
# The reliability statistics against each other and the controls: the three light-rotation
# scenarios (scenarios/light_rotation_*.ron) with one blend per statistic added beside EMA-only,
# High-LR, the paper's blend, switch and the fixed σ = 0.5 mix (all sharing one cache, so the
# comparison is paired within a run), over seeds; then nirc/scripts/seeds_summary.py (paired
# intervals against the fixed mix and the verdict of each statistic). Usage, from the
# repository root:
#   [SCENES="cornell_box courtyard corridor"] [STATISTICS="RelativeError"] [FLAGS="--resolution 32x18"] \
#   [PRETRAIN=160] [REFERENCE_SPP=N] [NIRC_EXTRA="paths: (train_records: 512)"] [JOBS=1] \
#   nirc/scripts/statistics_experiment.sh FLICKER OUT_DIR [SEED ...]
# (default seeds 1 2 3 4 5; PRETRAIN and REFERENCE_SPP replace the scenarios' pre-training
# frames and reference samples, NIRC_EXTRA adds settings to every Nirc method, FLAGS is passed to every `flicker run`, JOBS runs that many
# seeds side by side). OUT_DIR/scenarios holds the scenarios as played, OUT_DIR/summary.md the
# tables.
set -uo pipefail
bin=${1:?flicker binary}; out=${2:?output folder}; shift 2
seeds=("$@"); [ ${#seeds[@]} -eq 0 ] && seeds=(1 2 3 4 5)
mkdir -p "$out/runs" "$out/scenarios"
export FLICKER_CACHE_DIR=${FLICKER_CACHE_DIR:-$out/cache}
jobs=${JOBS:-1}
t0=$(date +%s)
for scene in ${SCENES:-cornell_box courtyard corridor}; do
  src="scenarios/light_rotation_$scene.ron"
  played="$out/scenarios/light_rotation_$scene.ron"
  # One more method per statistic, a copy of the fixed control's line (same cache settings).
  extra=""
  for s in ${STATISTICS:-RelativeError}; do
    extra="$extra$(grep -m1 'predictor: Fixed(0.5)' "$src" | sed "s/Fixed(0.5)/BlendBy($s)/")\n"
  done
  sed "/predictor: Fixed(0.5)/a\\
${extra%\\n}" "$src" >"$played"
  [ -n "${PRETRAIN:-}" ] && sed -i "s/pretrain_frames: [0-9]*/pretrain_frames: $PRETRAIN/" "$played"
  [ -n "${NIRC_EXTRA:-}" ] && sed -i "s/pretrain_frames:/$NIRC_EXTRA, pretrain_frames:/" "$played"
  [ -n "${REFERENCE_SPP:-}" ] && sed -i "s/reference: (spp: [0-9]*/reference: (spp: $REFERENCE_SPP/" "$played"
  for seed in "${seeds[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
    (
      run="$out/runs/$scene-seed$seed"
      # shellcheck disable=SC2086
      "$bin" run "$played" --seed "$seed" --out "$run" --quiet ${FLAGS:-} >"$run.log" 2>&1
      echo "$scene seed $seed: exit $? at $(( $(date +%s) - t0 )) s"
    ) &
  done
done
wait
python3 nirc/scripts/seeds_summary.py "$out/runs" 20 | tee "$out/summary.md"
