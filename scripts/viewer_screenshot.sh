#!/usr/bin/env bash
# The README's picture of the viewer: plays scenarios/showcase.ron (unless RUN is given) and
# saves headless Chromium's screenshot of its report.html, opened as a user opens it (on the
# event's frame), with the flags of the report tests (report/tests/common/browser.rs). The
# window is wide enough for the reference and the four methods in one row.
# Usage: scripts/viewer_screenshot.sh [RUN] [OUT.png]   (defaults: runs/showcase, docs/images/viewer.png)
set -euo pipefail
cd "$(dirname "$0")/.."
run=${1:-runs/showcase}
out=${2:-docs/images/viewer.png}
if [ $# -lt 1 ]; then
    cargo run --release --quiet -- run scenarios/showcase.ron --quiet
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
mkdir -p "$(dirname "$out")"
chromium --headless --no-sandbox --disable-gpu --disable-background-networking \
    --disable-component-update --disable-sync --no-first-run --hide-scrollbars \
    --force-device-scale-factor=1 --virtual-time-budget=10000 --window-size=1400,800 \
    --user-data-dir="$profile" --screenshot="$(realpath -m "$out")" \
    "file://$(realpath "$run")/report.html" 2>/dev/null
echo "wrote $out ($(stat -c %s "$out") bytes)"
