#!/usr/bin/env python3
"""The radiance scale of the Table 1 scenes against the paper's absolute thresholds.

  python3 scripts/termination_scale.py write DIR       # writes DIR/{door_gap,corridor}_sweep.ron
  flicker run DIR/door_gap_sweep.ron --out DIR/door_gap --quiet   (and corridor)
  python3 scripts/termination_scale.py fit DIR          # path length against absolute t, the fit

Each sweep runs variance bounding at absolute t = 1e-11 ... 1 (radiance_unit 1) beside path
tracing at 64x36, 2 frames after the 16 warm-up frames. `fit` finds, per paper threshold, the
lab's t* that gives the paper's path length (log-linear between sweep points), and the radiance
unit k = sqrt(geometric mean of t*/t) that maps the paper's t onto the lab's scene.
"""
import csv
import math
import statistics as st
import sys

PAPER = {"door_gap": (10, [4.05, 4.86, 7.41]), "corridor": (12, [1.97, 4.24, 4.88])}
SWEEP = [10.0 ** k for k in range(-11, 1)]


def write(out):
    for scene, (depth, _) in PAPER.items():
        methods = "\n".join(
            f'        Termination(rule: VarianceBounding(t: {t:g}), name: "vb_{t:g}"),' for t in SWEEP
        )
        with open(f"{out}/{scene}_sweep.ron", "w") as f:
            f.write(
                f'Scenario(\n    scene: Builtin("{scene}"),\n    resolution: (64, 36),\n    frames: 2,\n'
                f"    seed: 3,\n    max_depth: {depth},\n    methods: [\n{methods}\n"
                f'        Termination(rule: PathTracing, name: "pt"),\n    ],\n'
                f"    reference: (spp: 16, frames: None),\n)\n"
            )


def fit(out):
    for scene, (_, paper) in PAPER.items():
        rows = list(csv.DictReader(open(f"{out}/{scene}/frames.csv")))
        by = {}
        for r in rows:
            by.setdefault(r["method"], []).append(r)
        mean = lambda m, k: st.mean(float(r[k]) for r in by[m])
        ts = sorted((float(m[3:]), mean(m, "path_length")) for m in by if m.startswith("vb_"))
        print(f"{scene}: path length by absolute t (unit 1):")
        print("  " + ", ".join(f"{t:g}: {l:.2f}" for t, l in ts) + f"; path tracing {mean('pt', 'path_length'):.2f}")
        r = by[f"vb_{SWEEP[-1]:g}"]
        for k in ["cache_mean_p10", "cache_mean_p50", "cache_mean_p90", "cache_mean",
                  "cache_variance_p50", "cache_variance_p90", "cache_variance"]:
            print(f"  {k}: " + " / ".join(f"{float(x[k]):.2e}" for x in r))
        inc = [float(x["cache_incomplete_vertices"]) / (float(x["cache_incomplete_vertices"]) + float(x["cache_propagated_vertices"])) for x in r]
        print("  incomplete share of propagated vertices: " + " / ".join(f"{x:.3f}" for x in inc))
        ratios = []
        for tp, lp in zip([0.01, 0.1, 1.0], paper):
            star = next((10 ** (math.log10(t0) + (lp - l0) / (l1 - l0) * (math.log10(t1) - math.log10(t0)))
                         for (t0, l0), (t1, l1) in zip(ts, ts[1:]) if l0 <= lp <= l1), None)
            print(f"  paper t = {tp}: path length {lp} -> lab t* = {star:.2e}" if star else f"  paper t = {tp}: {lp} not reached")
            if star:
                ratios.append(star / tp)
        if ratios:
            k2 = math.exp(st.mean(math.log(x) for x in ratios))
            print(f"  t*/t: {', '.join(f'{x:.1e}' for x in ratios)}; k² = {k2:.2e}, radiance unit k = {math.sqrt(k2):.4f}")


{"write": write, "fit": fit}[sys.argv[1]](sys.argv[2])
