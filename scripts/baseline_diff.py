#!/usr/bin/env python3
"""Per-metric differences between two suite baselines (suites/baselines/*.json), frame by frame.

    python3 scripts/baseline_diff.py OLD.json NEW.json

For each metric (frame times left out: they are the machine's, not the method's), the largest
absolute difference of one frame's value between the two files (with its case, method and
values) and the mean absolute difference, over the adapters, cases, seeds and methods both hold.
To compare two commits' baselines: `git show A:suites/baselines/smoke.json > old.json`.
"""
import json
import sys
from collections import defaultdict


def main(old_path, new_path):
    old, new = (json.load(open(p)) for p in (old_path, new_path))
    worst = defaultdict(lambda: (0.0, None))
    total, count = defaultdict(float), defaultdict(int)
    for adapter, entry in old["adapters"].items():
        cases = new["adapters"].get(adapter, {}).get("cases", {})
        for case, data in entry["cases"].items():
            for seed_old, seed_new in zip(data["seeds"], cases.get(case, {}).get("seeds", [])):
                for method, metrics in seed_old["methods"].items():
                    for metric, values in metrics.items():
                        other = seed_new["methods"].get(method, {}).get(metric)
                        if metric == "frame_ms" or not isinstance(values, list) or other is None:
                            continue
                        for a, b in zip(values, other):
                            if a is None or b is None:
                                continue
                            d = abs(a - b)
                            total[metric] += d
                            count[metric] += 1
                            if d > worst[metric][0] or worst[metric][1] is None:
                                worst[metric] = (d, (case, seed_old["seed"], method, a, b))
    print("| metric | largest difference (case, seed, method: old → new) | mean difference | values |")
    print("|---|---|---|---|")
    for metric in sorted(count):
        d, (case, seed, method, a, b) = worst[metric]
        print(f"| {metric} | {d:.4g} ({case}, seed {seed}, {method}: {a:.4g} → {b:.4g}) "
              f"| {total[metric] / count[metric]:.4g} | {count[metric]} |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
