# Renders the scenes of bench/tests/mitsuba_matrix.rs with Mitsuba 3 (scalar_rgb) in one
# process: each scene `images` times with seeds seed, seed + 1, ..., so that every pixel's mean
# has a standard error from their spread. Usage: python3 scripts/mitsuba_matrix.py JOBS.json,
# JOBS a list of {"xml": ..., "spp": N per image, "images": K, "seed": S, "out": ...}; each `out`
# gets K x height x width x RGB little-endian f32, and one JSON line per job goes to stdout.
import json, os, struct, sys, time

import mitsuba as mi

mi.set_variant('scalar_rgb')
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_gltf_bsdf  # noqa: E402

mitsuba_gltf_bsdf.register()
for job in json.load(open(sys.argv[1])):
    t0 = time.perf_counter()
    scene = mi.load_file(job['xml'])
    with open(job['out'], 'wb') as f:
        for k in range(job['images']):
            image = mi.render(scene, spp=job['spp'], seed=job['seed'] + k)
            h, w, c = image.shape[0], image.shape[1], image.shape[2]
            values = list(image.array)
            rgb = [values[i * c + j] for i in range(w * h) for j in range(3)]
            f.write(struct.pack(f'<{len(rgb)}f', *rgb))
    print(json.dumps({'xml': job['xml'], 'width': w, 'height': h, 'images': job['images'],
                      'seconds': time.perf_counter() - t0, 'version': mi.__version__}), flush=True)
