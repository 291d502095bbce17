#!/usr/bin/env python3
"""The Table 1 analogue from termination scenario runs: python3 scripts/termination_table.py RUN..."""
import csv
import statistics as st
import sys

for run in sys.argv[1:]:
    rows = list(csv.DictReader(open(f"{run}/frames.csv")))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    print(f"\n{run}: median over frames\n")
    print("| method | path length | tc_trace ms | tc_propagate ms | tc_fold + tc_store ms | total GPU ms | rays | FLIP (frame 0) | SMAPE (mean, frames 1-3) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for m in methods:
        rs = [r for r in rows if r["method"] == m]
        med = lambda k: st.median(float(r[k]) for r in rs if r.get(k))
        flip = [float(r["flip"]) for r in rs if r["flip"]]
        smape = [float(r["smape"]) for r in rs if r["smape"]]
        print(f"| {m} | {st.mean(float(r['path_length']) for r in rs):.2f} | {med('gpu_ms_tc_trace'):.2f} | {med('gpu_ms_tc_propagate'):.2f} "
              f"| {med('gpu_ms_tc_fold') + med('gpu_ms_tc_store'):.2f} | {med('gpu_ms_total'):.2f} | {med('rays'):.0f} "
              f"| {flip[0] if flip else float('nan'):.3f} | {st.mean(smape) if smape else float('nan'):.3f} |")
    print(f"\nrecords filled (frame 0): {rows[0]['cache_records']}, cache bytes: {rows[0]['cache_bytes']}")
