#!/usr/bin/env bash
# Plays the tutorial's four scenarios (scenarios/tutorial/) as written and copies the pictures
# docs/tutorial.md shows into docs/images/tutorial/. Usage: scripts/tutorial_images.sh [FLICKER]
# (default target/release/flicker; build it first). Deterministic: the same commit and adapter
# give the same pictures.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
flicker="${1:-$root/target/release/flicker}"
out="$root/docs/images/tutorial"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
for step in 1_scene 2_event 3_methods 4_regions; do
    "$flicker" run "$root/scenarios/tutorial/$step.ron" --out "$work/$step" --cache-dir "$work/cache" --quiet >/dev/null
done
# Step 1: frame 0, the reference above 1-spp path tracing and its FLIP map.
cp "$work/1_scene/charts/crops_full_0000.png" "$out/1_scene.png"
# Step 2: frame 15, after the light turned.
cp "$work/2_event/charts/crops_full_0015.png" "$out/2_event.png"
# Step 3: frame 10, the frame of the turn, three methods; and SMAPE against the frame before.
cp "$work/3_methods/charts/crops_full_0010.png" "$out/3_methods.png"
cp "$work/3_methods/charts/frames_smape.png" "$out/3_methods_smape.png"
# Step 4: the red wall's region at frame 12, and FLIP against the reference per frame.
cp "$work/4_regions/charts/crops_red_wall_0012.png" "$out/4_regions_red_wall.png"
cp "$work/4_regions/charts/frames_flip.png" "$out/4_regions_flip.png"
"$flicker" --version 2>/dev/null || true
echo "commit $(git -C "$root" rev-parse --short HEAD); adapter: $(grep -o '"name": *"[^"]*"' "$work/4_regions/manifest.json" | head -1)"
# The numbers docs/tutorial.md quotes: mean FLIP and SMAPE before and after the event.
python3 - "$work/4_regions/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for m in s["methods"]:
    w = m["means"]
    print(m["method"], *(f'{k}: flip {w[k]["flip"]:.3f} smape {w[k]["smape"]:.3f}' for k in w if "flip" in w[k]))
PY
