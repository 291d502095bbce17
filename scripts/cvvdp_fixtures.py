#!/usr/bin/env python3
"""The independent check of flicker's JOD: renders tiny fixtures from our own scenarios and
scores them with `cvvdp`, the authors' PyTorch implementation of ColorVideoVDP.

    scripts/cvvdp_fixtures.py render FLICKER   play each fixtures/cvvdp/*.ron with the `flicker`
                                               binary and keep its reference and test EXRs
    scripts/cvvdp_fixtures.py score            score the committed fixtures with cvvdp and write
                                               scores.json (needs `pip install cvvdp`, CPU torch)
    scripts/cvvdp_fixtures.py time W H FRAMES  seconds cvvdp takes on the CPU for one sequence

metrics/tests/cvvdp_fixtures.rs reads scores.json and requires flicker's JOD within 0.01 of it,
without Python. The frames reach both metrics as the run's PNGs show them: radiance times the
exposure, clipped to [0, 1], sRGB-encoded (f32, not quantized), on the display named.
"""
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parent.parent
FIXTURES = REPO / "metrics" / "tests" / "fixtures" / "cvvdp"
# Each fixture is scored on these (display, exposure): the default, and a brighter, denser one.
SETTINGS = [("standard_fhd", 1.0), ("standard_4k", 4.0)]


def render(flicker):
    """Plays each fixture scenario and copies its reference and test frames beside it."""
    for ron in sorted(FIXTURES.glob("*.ron")):
        name = ron.stem
        with tempfile.TemporaryDirectory() as tmp:
            out = pathlib.Path(tmp) / "run"
            subprocess.run([flicker, "run", str(ron), "--out", str(out), "--cache-dir",
                            str(pathlib.Path(tmp) / "cache"), "--quiet"], check=True)
            manifest = json.loads((out / "manifest.json").read_text())
            method = manifest["methods"][0]
            dest = FIXTURES / name
            shutil.rmtree(dest, ignore_errors=True)
            for kind, src in (("reference", out / "reference"), ("test", out / "frames" / method)):
                (dest / kind).mkdir(parents=True)
                for exr in sorted(src.glob("*.exr")):
                    shutil.copy(exr, dest / kind / exr.name)
            (dest / "fps.txt").write_text(f"{1.0 / manifest['settings']['time_step']:.6f}\n")
        print(f"rendered {name}")


def load(folder):
    import numpy as np
    import OpenEXR

    frames = []
    for exr in sorted(folder.glob("*.exr")):
        with OpenEXR.File(str(exr)) as f:
            ch = f.channels()
            rgb = [np.asarray(ch[c].pixels, dtype=np.float32) for c in "RGB"] if "R" in ch \
                else [np.asarray(ch["RGBA"].pixels, dtype=np.float32)[..., i] for i in range(3)]
        frames.append(np.stack(rgb, axis=-1))
    return np.stack(frames)


def encode(frames, exposure):
    """As metrics::cvvdp::display_encoded: exposure, clip, sRGB (float32 throughout)."""
    import numpy as np

    c = np.clip(frames * np.float32(exposure), 0.0, 1.0).astype(np.float32)
    return np.where(c <= 0.0031308, c * np.float32(12.92),
                    np.float32(1.055) * np.power(c, np.float32(1.0 / 2.4)) - np.float32(0.055)
                    ).astype(np.float32)


def metric(display):
    import pycvvdp
    import torch

    return pycvvdp.cvvdp(display_name=display, device=torch.device("cpu"), quiet=True)


def score():
    from importlib.metadata import version

    import torch

    rows = []
    for dest in sorted(p for p in FIXTURES.iterdir() if p.is_dir()):
        reference, test = load(dest / "reference"), load(dest / "test")
        fps = float((dest / "fps.txt").read_text())
        for display, exposure in SETTINGS:
            jod, _ = metric(display).predict(encode(test, exposure), encode(reference, exposure),
                                             dim_order="FHWC", frames_per_second=fps)
            rows.append({"fixture": dest.name, "display": display, "exposure": exposure,
                         "fps": fps, "frames": int(reference.shape[0]), "jod": float(jod)})
            print(f"{dest.name} {display} x{exposure}: {float(jod):.6f} JOD")
    out = {"cvvdp": version("cvvdp"), "torch": torch.__version__, "device": "cpu", "scores": rows}
    (FIXTURES / "scores.json").write_text(json.dumps(out, indent=2) + "\n")


def timing(w, h, n):
    """cvvdp's CPU seconds for one n-frame sequence of w x h (random frames, median of 3)."""
    import numpy as np
    import torch

    torch.set_num_threads(1)
    rng = np.random.default_rng(1)
    ref = rng.random((n, h, w, 3), dtype=np.float32)
    test = np.clip(ref + rng.normal(0, 0.05, ref.shape).astype(np.float32), 0, 1)
    m = metric("standard_fhd")
    m.predict(test, ref, dim_order="FHWC", frames_per_second=30.0)
    times = []
    for _ in range(3):
        t = time.perf_counter()
        m.predict(test, ref, dim_order="FHWC", frames_per_second=30.0)
        times.append(time.perf_counter() - t)
    print(f"cvvdp {w}x{h} {n} frames, 1 thread: {sorted(times)[1]:.3f} s "
          f"({sorted(times)[1] / n * 1000:.1f} ms/frame)")


if __name__ == "__main__":
    match sys.argv[1:]:
        case ["render", flicker]:
            render(flicker)
        case ["score"]:
            score()
        case ["time", w, h, n]:
            timing(int(w), int(h), int(n))
        case _:
            sys.exit(__doc__)
