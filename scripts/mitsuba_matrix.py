# Renders the scenes of systems/tests/mitsuba_matrix.rs with Mitsuba 3 (scalar_rgb) in one
# process, each under the `moment` integrator so every pixel has its sample mean and second
# moment. Usage: python3 scripts/mitsuba_matrix.py JOBS.json, JOBS a list of
# {"xml": ..., "spp": N, "seed": S, "out": ...}; each `out` gets height x width x 9 little-endian
# f32 (R, G, B, mean RGB, second moment RGB), and one JSON line per job goes to stdout.
import json, os, struct, sys, time

import mitsuba as mi

mi.set_variant('scalar_rgb')
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_gltf_bsdf  # noqa: E402

mitsuba_gltf_bsdf.register()
for job in json.load(open(sys.argv[1])):
    t0 = time.perf_counter()
    scene = mi.load_file(job['xml'])
    image = mi.render(scene, spp=job['spp'], seed=job['seed'])
    h, w, c = image.shape[0], image.shape[1], image.shape[2]
    values = list(image.array)
    with open(job['out'], 'wb') as f:
        f.write(struct.pack(f'<{len(values)}f', *values))
    print(json.dumps({'xml': job['xml'], 'width': w, 'height': h, 'channels': c,
                      'seconds': time.perf_counter() - t0, 'version': mi.__version__}), flush=True)
