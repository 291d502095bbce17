# Renders a scene that `flicker bench` exported to Mitsuba 3 XML with the scalar_rgb variant and
# prints one JSON line: seconds of the timed render, paths traced, Dr.Jit's thread count and the
# image's mean RGB. Usage: python3 scripts/mitsuba_render.py SCENE.xml SPP OUT.exr
# (`pip install mitsuba`; flicker bench runs it when `python3 -c "import mitsuba"` works).
import json, os, sys, time

import drjit as dr
import mitsuba as mi

mi.set_variant('scalar_rgb')
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_gltf_bsdf  # noqa: E402  (flicker's BSDF, for materials that are not Lambertian)

mitsuba_gltf_bsdf.register()
xml, spp, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
scene = mi.load_file(xml)
mi.render(scene, spp=1)  # one-time set-up (BVH build, film) stays out of the timing
t0 = time.perf_counter()
image = mi.render(scene, spp=spp, seed=1)
seconds = time.perf_counter() - t0
mi.Bitmap(image).write(out)
h, w = image.shape[0], image.shape[1]
values = list(image.array)
channels = image.shape[2]
mean = [sum(values[c::channels]) / (w * h) for c in range(3)]
print(json.dumps({'seconds': seconds, 'paths': w * h * spp, 'threads': dr.thread_count(), 'mean_rgb': mean,
                  'version': mi.__version__}))
