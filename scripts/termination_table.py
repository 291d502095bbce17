#!/usr/bin/env python3
"""The Table 1 analogue from termination scenario runs: python3 scripts/termination_table.py RUN...

Rules of one cache key share one cache (methods/termination/README.md): its passes (tc_propagate,
tc_fold, tc_insert, tc_store) are in the row of its first method only. A rule's frame time is its
own tc_trace plus its cache's passes, taken from the nearest row at or above it that has them (the
scenarios list the shared rules first and path tracing, with its own cache, last)."""
import csv
import math
import statistics as st
import sys

CACHE = ("tc_propagate", "tc_fold", "tc_insert", "tc_store")

for run in sys.argv[1:]:
    rows = list(csv.DictReader(open(f"{run}/frames.csv")))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    print(f"\n{run}: median over frames\n")
    print("| method | path length | tracer (tc_trace) ms | propagation (tc_propagate) ms | fold + insert + store ms | frame ms | rays | FLIP (frame 0) | SMAPE (mean, frames 1-3) |")
    print("|---|---|---|---|---|---|---|---|---|")
    cache = None
    for m in methods:
        rs = [r for r in rows if r["method"] == m]
        med = lambda k: st.median(float(r[k]) for r in rs if r.get(k)) if any(r.get(k) for r in rs) else math.nan
        own = {p: med(f"gpu_ms_{p}") for p in CACHE}
        shared = not math.isnan(own["tc_propagate"])
        if shared:
            cache = own
        flip = [float(r["flip"]) for r in rs if r["flip"]]
        smape = [float(r["smape"]) for r in rs if r["smape"]]
        show = lambda x: f"{x:.2f}" if shared else "(shared)"
        frame = med("gpu_ms_tc_trace") + sum(cache.values())
        print(f"| {m} | {st.mean(float(r['path_length']) for r in rs):.2f} | {med('gpu_ms_tc_trace'):.2f} | {show(own['tc_propagate'])} "
              f"| {show(own['tc_fold'] + own['tc_insert'] + own['tc_store'])} | {frame:.2f} | {med('rays'):.0f} "
              f"| {flip[0] if flip else float('nan'):.3f} | {st.mean(smape) if smape else float('nan'):.3f} |")
    print(f"\nrecords filled (frame 0): {rows[0]['cache_records']}, cache bytes: {rows[0]['cache_bytes']}")
