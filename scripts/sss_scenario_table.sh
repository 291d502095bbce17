#!/usr/bin/env bash
# Table 7.3's analogue from the SSS scenarios themselves (methods/sss/README.md): plays
# scenarios/sss_flash.ron, sss_toggle.ron and sss_boids.ron at their own size (96x54, 60 frames)
# into OUT/NAME and prints the table (mean spp, SSS pass ms, PSNR against pass_2048, SMAPE);
# per-frame SMAPE lands in OUT/NAME/sss_smape.csv. With SEEDS ("1 2 3"), each scenario is played
# once per seed into OUT/NAME/seedS and the table gives per-seed values, means and Table 7.3's
# relations judged over the seeds.
#
#   scripts/sss_scenario_table.sh [OUT] [PROFILE] [SEEDS]   PROFILE: debug (default) or release
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$repo/runs/sss_table}"
profile="${2:-debug}"
seeds="${3:-}"
flag=""
[ "$profile" = release ] && flag="--release"
cd "$repo"
cargo build $flag -p flicker --bin flicker
cargo build $flag -p systems --example sss_scenario_table
for name in sss_flash sss_toggle sss_boids; do
    if [ -z "$seeds" ]; then
        "target/$profile/flicker" run "scenarios/$name.ron" --out "$out/$name" --quiet
    else
        for seed in $seeds; do
            "target/$profile/flicker" run "scenarios/$name.ron" --seed "$seed" \
                --out "$out/$name/seed$seed" --quiet
        done
    fi
done
"target/$profile/examples/sss_scenario_table" "$out/sss_flash" "$out/sss_toggle" "$out/sss_boids"
