#!/usr/bin/env python3
"""Per-window means of a dynamic termination run (README "Dynamic scenes"):
python3 scripts/termination_dynamics.py RUN START:END [START:END ...]
Each START:END is a half-open frame window; prints one table per column."""
import csv
import statistics as st
import sys

run, windows = sys.argv[1], [tuple(map(int, w.split(":"))) for w in sys.argv[2:]]
rows = list(csv.DictReader(open(f"{run}/frames.csv")))
methods = list(dict.fromkeys(r["method"] for r in rows))
for col in ["flip", "smape", "path_length", "cache_mean", "cache_variance", "cache_bias2"]:
    print(f"\n{col}\n")
    print("| method | " + " | ".join(f"frames {a}-{b - 1}" for a, b in windows) + " |")
    print("|---|" + "---:|" * len(windows))
    for m in methods:
        cells = []
        for a, b in windows:
            v = [float(r[col]) for r in rows if r["method"] == m and a <= int(r["frame"]) < b and r.get(col)]
            cells.append(f"{st.mean(v):.3f}" if v else "")
        print(f"| {m} | " + " | ".join(cells) + " |")
