#!/usr/bin/env python3
"""Renders a `flicker export` package with Blender's Cycles (the `bpy` module, CPU, headless): an
independent renderer playing the exported glTF, for docs/lab/blender-cycles.md.

    .venv/bin/python scripts/blender_cycles.py PACKAGE --out DIR --spp N [--times CSV]
        [--lighting COMPAT|RAW|SPEC]

Blender imports scene.glb with its own glTF importer (KHR_lights_punctual, the materials as
Principled BSDFs, the `transforms` and `properties` animations, KHR_animation_pointer included)
and plays the animations at the package's frame times (the importer leaves only the first
animation assigned: the script assigns `properties` too, and scales animated point-light powers
as the importer scales static ones, which it does not do itself). Only what glTF cannot say is set from
the package: the environment (the scene's `extras.flicker_environment`), a sun's angular radius
(`extras.flicker_angular_radius`), the camera (each frame record's position, target and vertical
field of view; the importer's camera is replaced so that the aspect ratio cannot differ), and
emission from front faces only (flicker's convention; Cycles emits from both unless told), and
the render settings that match flicker's estimator: `max_depth - 1` bounces (the same paths), a box pixel filter
one pixel wide, no clamping, no glossy blur, no denoising, linear EXR without a view transform.

Light units: `--lighting COMPAT` (the default) imports a point light's glTF intensity I as a
Blender power of 4 pi I watts, which Cycles renders as I W/sr, and a sun's intensity as W/m²:
flicker's radiometric reading of the same numbers. `SPEC` divides by 683 lm/W (glTF's photometric
candela and lux), `RAW` takes the number as Blender watts.

Writes DIR/NNNN.exr and, with --times, a `flicker measure --timings` CSV of each frame's render
time (Cycles' wall clock on the CPU).
"""

import argparse
import json
import math
import os
import struct
import sys
import time

import bpy
from mathutils import Vector


def glb_json(path):
    """The JSON chunk of a binary glTF file."""
    with open(path, "rb") as f:
        data = f.read()
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        sys.exit(f"{path}: not a binary glTF file")
    length, kind = struct.unpack_from("<I4s", data, 12)
    if kind != b"JSON":
        sys.exit(f"{path}: the first chunk is not JSON")
    return json.loads(data[20 : 20 + length])


def gl_to_blender(v):
    """glTF's +Y up to Blender's +Z up, as the importer converts."""
    return Vector((v[0], -v[2], v[1]))


def one_sided_emission():
    """flicker's emitters emit from their front face only (CONVENTIONS.md); Cycles' emission
    shader emits from both. Every material with an emission input gets its strength times
    (1 - Backfacing)."""
    changed = 0
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        tree = mat.node_tree
        for node in list(tree.nodes):
            strength = node.inputs.get("Emission Strength") if node.type == "BSDF_PRINCIPLED" else None
            if strength is None or strength.is_linked:
                continue
            geometry = tree.nodes.new("ShaderNodeNewGeometry")
            front = tree.nodes.new("ShaderNodeMath")
            front.operation = "SUBTRACT"
            front.inputs[0].default_value = 1.0
            tree.links.new(geometry.outputs["Backfacing"], front.inputs[1])
            scaled = tree.nodes.new("ShaderNodeMath")
            scaled.operation = "MULTIPLY"
            scaled.inputs[1].default_value = strength.default_value
            tree.links.new(front.outputs[0], scaled.inputs[0])
            tree.links.new(scaled.outputs[0], strength)
            changed += 1
    return changed


def assign_all_actions():
    """The importer makes one action per glTF animation but leaves only the first active;
    `properties` (KHR_animation_pointer: light intensity and colour, material factors) is created
    with a slot per animated datablock and left unassigned. Assign every action's slots to
    their datablocks so that both animations play."""
    assigned = 0
    for action in bpy.data.actions:
        for slot in action.slots:
            for user in slot.users():
                data = user.animation_data or user.animation_data_create()
                if data.action != action:
                    data.action = action
                    data.action_slot = slot
                    assigned += 1
    return assigned


def fix_pointer_energy(lighting):
    """Blender 5.0's importer converts an animated point or spot light's intensity as a
    directional light's (animation_pointer.py compares the glTF type "point" with "POINT"), so
    the animated power lacks the static import's factor 4 pi (COMPAT, SPEC). Put it back."""
    factor = 1.0 if lighting == "RAW" else 4.0 * math.pi
    fixed = 0
    for action in bpy.data.actions:
        for slot in action.slots:
            if slot.target_id_type != "LIGHT":
                continue
            if not any(u.type in ("POINT", "SPOT") for u in slot.users()):
                continue
            for layer in action.layers:
                for strip in layer.strips:
                    bag = strip.channelbag(slot)
                    for curve in bag.fcurves if bag else []:
                        if curve.data_path != "energy":
                            continue
                        for key in curve.keyframe_points:
                            key.co[1] *= factor
                            key.handle_left[1] *= factor
                            key.handle_right[1] *= factor
                        fixed += 1
    return fixed


def main():
    argv = sys.argv[1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("package")
    parser.add_argument("--out", required=True)
    parser.add_argument("--spp", type=int, required=True)
    parser.add_argument("--times")
    parser.add_argument("--lighting", default="COMPAT", choices=["COMPAT", "RAW", "SPEC"])
    parser.add_argument("--threads", type=int, default=0, help="0: all cores")
    parser.add_argument(
        "--two-sided-emission",
        action="store_true",
        help="keep Cycles' emission from both faces (flicker's emitters are one-sided)",
    )
    args = parser.parse_args(argv)

    with open(os.path.join(args.package, "manifest.json")) as f:
        manifest = json.load(f)
    frames, fps = manifest["frames"], manifest["fps"]
    width, height = manifest["resolution"]
    glb = os.path.join(args.package, manifest.get("scene", "scene.glb"))
    doc = glb_json(glb)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    # The importer converts times to frames with the scene's rate: set it first.
    scene.render.fps = int(round(fps))
    scene.render.fps_base = scene.render.fps / fps
    bpy.ops.import_scene.gltf(filepath=glb, export_import_convert_lighting_mode=args.lighting)

    print(f"actions assigned: {assign_all_actions()}", flush=True)
    print(f"animated light powers fixed: {fix_pointer_energy(args.lighting)}", flush=True)
    # What glTF cannot say.
    if not args.two_sided_emission:
        print(f"one-sided emission: {one_sided_emission()} materials", flush=True)
    env = doc["scenes"][0].get("extras", {}).get("flicker_environment", [0.0, 0.0, 0.0])
    world = bpy.data.worlds.new("environment")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (env[0], env[1], env[2], 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.world = world
    for light in doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", []):
        radius = light.get("extras", {}).get("flicker_angular_radius")
        if radius is not None and light.get("name") in bpy.data.lights:
            bpy.data.lights[light["name"]].angle = 2.0 * radius

    camera_data = bpy.data.cameras.new("records")
    camera_data.sensor_fit = "VERTICAL"
    camera_data.clip_start, camera_data.clip_end = 0.01, 1000.0
    camera = bpy.data.objects.new("records", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args.spp
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = int(manifest.get("seed", 0))
    # flicker's max_depth counts path vertices after the camera's (its primary hit is depth 0,
    # with next-event estimation at depths 0..max_depth-1); Cycles counts bounces, 0 being
    # direct light only: max_depth - 1 bounces are the same paths.
    depth = max(int(manifest.get("max_depth", 8)) - 1, 0)
    cycles.max_bounces = depth
    cycles.diffuse_bounces = depth
    cycles.glossy_bounces = depth
    cycles.transmission_bounces = depth
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = depth
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    cycles.film_exposure = 1.0
    scene.render.threads_mode = "FIXED" if args.threads else "AUTO"
    if args.threads:
        scene.render.threads = args.threads
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.color_mode = "RGB"
    settings.exr_codec = "ZIP"

    os.makedirs(args.out, exist_ok=True)
    rows = ["frame,ms"]
    for k in range(frames):
        with open(os.path.join(args.package, "frames", f"{k:04d}.json")) as f:
            record = json.load(f)
        scene.frame_set(k)
        cam = record["camera"]
        position, target = gl_to_blender(cam["position"]), gl_to_blender(cam["target"])
        camera.location = position
        camera.rotation_mode = "QUATERNION"
        camera.rotation_quaternion = (target - position).to_track_quat("-Z", "Y")
        camera_data.angle_y = cam["vfov"]
        scene.render.filepath = os.path.join(os.path.abspath(args.out), f"{k:04d}.exr")
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        ms = (time.perf_counter() - start) * 1000.0
        rows.append(f"{k},{ms:.3f}")
        print(f"frame {k}: {ms:.0f} ms", flush=True)
    if args.times:
        with open(args.times, "w") as f:
            f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
