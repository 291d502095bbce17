#!/usr/bin/env bash
# Same results between two commits: runs every shipped scenario at 32x18, 4 frames, seed 1 with
# each commit's `flicker` and compares the runs. EXRs (method frames, method images, references)
# must be byte-identical and the metric columns of frames.csv identical; timing columns (cpu_ms,
# gpu_ms_*, wall_ms_*, nirc_ms) are left out.
#
#   scripts/same_results.sh BEFORE AFTER [WORK]   build both commits (git worktrees) and compare
#   scripts/same_results.sh run FLICKER OUT [DIR] run every scenario (of DIR, default scenarios/)
#                                                 with one binary into OUT
#   scripts/same_results.sh compare OUT_A OUT_B   compare two such folders
#   scripts/same_results.sh pixels OUT_A OUT_B    the same, EXRs by channels and pixels (bit for
#                                                 bit) where their bytes differ (a new layout)
#
# Each commit renders its own references (separate cache folders), so references are compared
# too. Exit status 0 when everything matches, 1 when something differs.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
SIZE=32x18
FRAMES=4
SEED=1

run_all() {
    local bin="$1" out="$2" dir="${3:-$repo/scenarios}"
    mkdir -p "$out"
    local failed=0
    for s in "$dir"/*.ron; do
        local name
        name="$(basename "$s" .ron)"
        echo "== $name" >&2
        if ! "$bin" run "$s" --frames "$FRAMES" --resolution "$SIZE" --seed "$SEED" --out "$out/runs/$name" \
            --cache-dir "$out/cache" --quiet >"$out/$name.log" 2>&1; then
            echo "   failed (see $out/$name.log)" >&2
            echo "$name" >>"$out/failed.txt"
            failed=1
        fi
    done
    return 0
}

compare() {
    python3 "$repo/scripts/same_results_compare.py" "$1" "$2"
}

case "${1:-}" in
    run)
        [ $# -ge 3 ] || { echo "usage: $0 run FLICKER OUT [SCENARIOS_DIR]" >&2; exit 2; }
        run_all "$2" "$3" "${4:-}"
        ;;
    compare)
        [ $# -eq 3 ] || { echo "usage: $0 compare OUT_A OUT_B" >&2; exit 2; }
        compare "$2" "$3"
        ;;
    pixels)
        [ $# -eq 3 ] || { echo "usage: $0 pixels OUT_A OUT_B" >&2; exit 2; }
        python3 "$repo/scripts/same_results_compare.py" --pixels "$2" "$3"
        ;;
    ""|-h|--help)
        sed -n 2,15p "$0" | sed 's/^# \{0,1\}//'
        exit 2
        ;;
    *)
        [ $# -ge 2 ] || { echo "usage: $0 BEFORE AFTER [WORK]" >&2; exit 2; }
        work="${3:-$repo/target/same_results}"
        mkdir -p "$work"
        # Resolved once: a commit made while this runs must not change what is compared.
        before="$(git -C "$repo" rev-parse --short "$1^{commit}")"
        after="$(git -C "$repo" rev-parse --short "$2^{commit}")"
        for sha in "$before" "$after"; do
            commit="$sha"
            tree="$work/src-$sha"
            [ -d "$tree" ] || git -C "$repo" worktree add --detach "$tree" "$commit" >/dev/null
            # A commit's binary and runs are kept (by commit hash): a second comparison against
            # the same commit reuses them.
            if [ ! -x "$work/flicker-$sha" ]; then
                # One target folder: dependencies build once for both commits.
                CARGO_TARGET_DIR="$repo/target/same_results_build" cargo build --release --locked --manifest-path "$tree/Cargo.toml" --bin flicker >&2
                cp "$repo/target/same_results_build/release/flicker" "$work/flicker-$sha"
            fi
            if [ ! -e "$work/out-$sha/done" ]; then
                rm -rf "$work/out-$sha"
                run_all "$work/flicker-$sha" "$work/out-$sha" "$tree/scenarios"
                touch "$work/out-$sha/done"
            fi
        done
        compare "$work/out-$before" "$work/out-$after"
        ;;
esac
