#!/usr/bin/env python3
"""The jackknife scenarios' relations over seeds (media/README.md, "The jackknife scenarios over
seeds"): python3 scripts/volume_relations.py ROOT, where ROOT/SCENARIO/sSEED/frames.csv are the
runs of scenarios/volume_explosion_supervoxel.ron, volume_shadow.ron, volume_mis_exact.ron and
volume_mis_exact_homogeneous.ron. Per pair a/b of methods: the per-seed log ratio of a column,
its mean and the one-sided 95% Student-t upper bound over the seeds."""
import csv
import glob
import math
import os
import sys

T95 = {1: 6.314, 2: 2.920, 3: 2.353, 4: 2.132}  # one-sided 95% t quantiles by degrees of freedom


def runs(root, scenario):
    out = []
    for d in sorted(glob.glob(os.path.join(root, scenario, "s*"))):
        with open(os.path.join(d, "frames.csv")) as f:
            out.append({r["method"]: r for r in csv.DictReader(f)})
    return out


def report(rs, scenario, column, pairs):
    for a, b in pairs:
        d = [math.log(float(r[a][column]) / float(r[b][column])) for r in rs]
        n = len(d)
        m = sum(d) / n
        sd = math.sqrt(sum((x - m) ** 2 for x in d) / (n - 1))
        up = m + T95[n - 1] * sd / math.sqrt(n)
        ratios = ", ".join(f"{math.exp(x):.3f}" for x in d)
        print(f"{scenario} {column}: {a} / {b}: ratio per seed {ratios}; bound {math.exp(up):.3f}")


def main(root):
    e = runs(root, "volume_explosion_supervoxel")
    bias = [("jackknife_sv16", "biased_rm_sv16"), ("jackknife_sv12", "biased_rm_sv12"),
            ("jackknife_sv16", "naive_sv16"), ("jackknife_sv12", "naive_sv12"),
            ("jackknife_sv12", "jackknife_sv16"), ("naive_sv12", "naive_sv16")]
    report(e, "explosion", "rms_bias", bias)
    std = [("jackknife_sv16", "unbiased_rm_sv16"), ("jackknife_sv12", "unbiased_rm_sv12"),
           ("naive_sv16", "jackknife_sv16")]
    report(e, "explosion", "mean_std", std)
    p = "volume_pt_free_flight_"
    shadow = [(p + "shadow_jackknife_m2_n10_16spp", p + "16spp"),
              (p + "shadow_jackknife_m2_n10_16spp", p + "shadow_track_length_16spp"),
              (p + "shadow_jackknife_m3_n8_16spp", p + "16spp"),
              (p + "shadow_jackknife_m2_step0.5_16spp", p + "16spp")]
    report(runs(root, "volume_shadow"), "shadow", "flip", shadow)
    q = "volume_pt_"
    mis = [(q + "jackknife_eq9_exact_t_16spp", q + "jackknife_eq9_16spp"),
           (q + "naive_eq9_exact_t_16spp", q + "naive_eq9_16spp"),
           (q + "jackknife_eq9_16spp", q + "free_flight_16spp"),
           (q + "naive_eq9_16spp", q + "free_flight_16spp"),
           (q + "jackknife_eq9_exact_t_16spp", q + "free_flight_16spp"),
           (q + "naive_eq9_16spp", q + "jackknife_eq9_16spp")]
    for s in ["volume_mis_exact", "volume_mis_exact_homogeneous"]:
        rs = runs(root, s)
        for c in ["flip", "mse"]:
            report(rs, s, c, mis)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: volume_relations.py ROOT (ROOT/SCENARIO/sSEED/frames.csv)")
    main(sys.argv[1])
