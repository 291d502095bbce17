#!/usr/bin/env python3
"""Compares two folders written by `scripts/same_results.sh run`: every EXR byte for byte, and
frames.csv without its timing columns. Prints each difference; exit 1 if there is any.

With --pixels, an EXR whose bytes differ passes when its channels and pixels are equal bit for bit
(a change of file layout, e.g. tiles to scan lines); it needs Python's OpenEXR package."""
import csv
import pathlib
import sys

TIMING = ("cpu_ms", "nirc_ms")
TIMING_PREFIXES = ("gpu_ms_", "wall_ms_")


def metric_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    keep = lambda c: c not in TIMING and not c.startswith(TIMING_PREFIXES)
    return [{k: v for k, v in r.items() if keep(k)} for r in rows]


def exr_pixels(path):
    """Channel name -> raw pixel bytes (float32 or half, as stored)."""
    import OpenEXR  # only for --pixels

    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {name: (c.pixels.dtype.str, c.pixels.shape, c.pixels.tobytes()) for name, c in f.channels().items()}


def main(a, b, pixels=False):
    a, b = pathlib.Path(a), pathlib.Path(b)
    problems = []
    relaid = 0
    for failed in (a / "failed.txt", b / "failed.txt"):
        if failed.exists():
            problems.append(f"{failed}: runs failed: {failed.read_text().split()}")
    runs_a = sorted(p.name for p in (a / "runs").iterdir()) if (a / "runs").exists() else []
    runs_b = sorted(p.name for p in (b / "runs").iterdir()) if (b / "runs").exists() else []
    if runs_a != runs_b:
        problems.append(f"different runs: {sorted(set(runs_a) ^ set(runs_b))}")
    compared = 0
    for run in sorted(set(runs_a) & set(runs_b)):
        ra, rb = a / "runs" / run, b / "runs" / run
        exr_a = sorted(p.relative_to(ra) for p in ra.rglob("*.exr"))
        exr_b = sorted(p.relative_to(rb) for p in rb.rglob("*.exr"))
        if exr_a != exr_b:
            problems.append(f"{run}: different EXR files: {sorted(map(str, set(exr_a) ^ set(exr_b)))}")
        for rel in sorted(set(exr_a) & set(exr_b)):
            compared += 1
            if (ra / rel).read_bytes() != (rb / rel).read_bytes():
                if pixels and exr_pixels(ra / rel) == exr_pixels(rb / rel):
                    relaid += 1
                else:
                    problems.append(f"{run}/{rel}: {'pixels' if pixels else 'bytes'} differ")
        csv_a, csv_b = ra / "frames.csv", rb / "frames.csv"
        if not (csv_a.exists() and csv_b.exists()):
            problems.append(f"{run}: frames.csv missing")
            continue
        rows_a, rows_b = metric_rows(csv_a), metric_rows(csv_b)
        if len(rows_a) != len(rows_b):
            problems.append(f"{run}/frames.csv: {len(rows_a)} vs {len(rows_b)} rows")
        for i, (x, y) in enumerate(zip(rows_a, rows_b)):
            if x != y:
                diff = {k: (x.get(k), y.get(k)) for k in set(x) | set(y) if x.get(k) != y.get(k)}
                problems.append(f"{run}/frames.csv row {i + 2}: {diff}")
    for p in problems:
        print(p)
    if pixels:
        print(f"{relaid} EXRs differ in bytes only (same channels and pixels, bit for bit)")
    print(f"{len(set(runs_a) & set(runs_b))} runs, {compared} EXRs compared, {len(problems)} differences")
    return 1 if problems else 0


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--pixels"]
    if len(args) != 2:
        sys.exit("usage: same_results_compare.py [--pixels] OUT_A OUT_B")
    sys.exit(main(args[0], args[1], pixels="--pixels" in sys.argv[1:]))
