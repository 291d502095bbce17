#!/usr/bin/env bash
# Table 7.3's analogue from the SSS scenarios themselves (render/src/sss/README.md): plays
# scenarios/sss_flash.ron, sss_toggle.ron and sss_boids.ron at their own size (96x54, 60 frames)
# into OUT/NAME and prints the table (mean spp, SSS pass ms, PSNR against pass_2048, SMAPE);
# per-frame SMAPE lands in OUT/NAME/sss_smape.csv.
#
#   scripts/sss_scenario_table.sh [OUT] [PROFILE]   PROFILE: debug (default) or release
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$repo/runs/sss_table}"
profile="${2:-debug}"
flag=""
[ "$profile" = release ] && flag="--release"
cd "$repo"
cargo build $flag -p flicker --bin flicker
cargo build $flag -p systems --example sss_scenario_table
for name in sss_flash sss_toggle sss_boids; do
    "target/$profile/flicker" run "scenarios/$name.ron" --out "$out/$name" --quiet
done
"target/$profile/examples/sss_scenario_table" "$out/sss_flash" "$out/sss_toggle" "$out/sss_boids"
