#!/usr/bin/env python3
"""A small outside method for flicker's walk-through (docs/walkthrough.md): temporal accumulation
of a `flicker export` package's 1-spp radiance, reprojected with the package's motion vectors.

Per frame k, each pixel's history is fetched where the surface was in frame k-1 (motion vectors:
previous = current + motion, in pixels, CONVENTIONS.md), bilinearly, and blended with the new
sample by an exponential moving average whose weight is 1/n for the first frames of a history and
then `--alpha` (Karis 2014, "High-quality temporal supersampling"; Yang et al. 2020, "A survey of
temporal antialiasing techniques"). The history is dropped where the reprojected point falls off
the screen or its depth disagrees with the previous frame's (a disocclusion). No clamping to the
neighbourhood: the lag after a light changes is what flicker's windows show.

Writes OUT/NNNN.exr (linear RGB, the package's frame numbers) and a timings CSV that
`flicker measure --timings` reads: `frame,ms,reproject,blend`, where `ms` is the whole frame
(reading and writing the EXRs included: the rest becomes flicker's pass `other`).

Needs numpy and the OpenEXR Python bindings (scripts/setup.sh installs them).
"""

import argparse
import json
import os
import time

import numpy as np
import OpenEXR


def read_rgb(path):
    with OpenEXR.File(path) as f:
        return np.array(f.channels()["RGB"].pixels, dtype=np.float32)


def write_rgb(path, rgb):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb, dtype=np.float32)}).write(path)


def bilinear(image, x, y):
    """`image` (h, w, c) at continuous pixel coordinates (x, y) of pixel centres, clamped."""
    h, w = image.shape[:2]
    x0 = np.clip(np.floor(x).astype(int), 0, w - 1)
    y0 = np.clip(np.floor(y).astype(int), 0, h - 1)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx = np.clip(x - x0, 0.0, 1.0)[..., None]
    fy = np.clip(y - y0, 0.0, 1.0)[..., None]
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("package", help="a folder written by `flicker export`")
    parser.add_argument("--out", required=True, help="folder for the accumulated frames")
    parser.add_argument("--times", required=True, help="the timings CSV to write")
    parser.add_argument("--alpha", type=float, default=0.1, help="the blend weight's floor")
    parser.add_argument(
        "--depth-tolerance", type=float, default=0.1, help="relative depth change of a disocclusion"
    )
    args = parser.parse_args()

    with open(os.path.join(args.package, "manifest.json")) as f:
        frames = json.load(f)["frames"]
    inputs = os.path.join(args.package, "inputs")
    os.makedirs(args.out, exist_ok=True)
    rows = ["frame,ms,reproject,blend"]
    history = prev_depth = count = None
    for k in range(frames):
        start = time.perf_counter()
        name = f"{k:04d}.exr"
        radiance = read_rgb(os.path.join(inputs, "radiance", name))
        motion = read_rgb(os.path.join(inputs, "motion", name))
        depth = read_rgb(os.path.join(inputs, "depth", name))[..., 0]
        h, w = depth.shape

        t0 = time.perf_counter()
        if history is None:
            valid = np.zeros((h, w), dtype=bool)
            fetched = np.zeros_like(radiance)
            prev_count = np.zeros((h, w), dtype=np.float32)
        else:
            ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
            # Pixel centres: (x + 0.5) + motion is where the point was, minus 0.5 in indices.
            px, py = xs + motion[..., 0], ys + motion[..., 1]
            inside = (px > -0.5) & (px < w - 0.5) & (py > -0.5) & (py < h - 0.5)
            ix = np.clip(np.rint(px).astype(int), 0, w - 1)
            iy = np.clip(np.rint(py).astype(int), 0, h - 1)
            before = prev_depth[iy, ix]
            both_miss = np.isinf(depth) & np.isinf(before)
            with np.errstate(invalid="ignore"):
                close = np.abs(before - depth) <= args.depth_tolerance * depth
            valid = inside & (both_miss | close)
            fetched = bilinear(history, px, py)
            prev_count = count[iy, ix]
        t1 = time.perf_counter()

        count = np.where(valid, prev_count + 1.0, 1.0).astype(np.float32)
        weight = np.maximum(1.0 / count, args.alpha)[..., None]
        history = np.where(valid[..., None], fetched + weight * (radiance - fetched), radiance)
        prev_depth = depth
        t2 = time.perf_counter()

        write_rgb(os.path.join(args.out, name), history)
        end = time.perf_counter()
        ms = lambda a, b: f"{(b - a) * 1000.0:.6f}"
        rows.append(f"{k},{ms(start, end)},{ms(t0, t1)},{ms(t1, t2)}")
    with open(args.times, "w") as f:
        f.write("\n".join(rows) + "\n")
    print(f"wrote {frames} frames to {args.out} and their times to {args.times}")


if __name__ == "__main__":
    main()
