"""The reference renderer against Blender Cycles on the same scenes: a GGX sphere (alpha 0.2) under the
built-in sky, and a GGX sphere (alpha 0.3, F = 1) in the scene of ../shared/data/realref (constant
environment 0.3 and a directional light of irradiance 3, as in docs/render-speed.md's comparison with
Mitsuba 3), 256 x 256, 64 spp, direct lighting, CPU. Run with the bpy venv's python (make bench):

    python cycles_compare.py FACETFIT_BINARY OUTPUT.md
"""
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import bpy  # Blender as a Python module (bpy wheel)
import mathutils

SIZE, SPP, ALPHA, RUNS = 256, 64, 0.2, 3


# The realref scene's light: toward (0.3, 1, 0.5) in facetfit's y-up world, irradiance 3; environment 0.3.
SUN = (0.3, 1.0, 0.5)
REALREF_ALPHA = 0.3


def facetfit_times(binary, work, realref=False):
    sky = os.path.join(work, "sky.exr")
    subprocess.run([binary, "render", "-o", os.path.join(work, "warm.exr"), "--save-sky", sky, "--spp", "1",
                    "--width", "8", "--height", "8"], check=True, capture_output=True)
    scene = {
        "camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30, "width": SIZE, "height": SIZE},
        "render": {"spp": SPP, "seed": 1},
        "environment": {"file": "sky.exr"},
        "materials": {"m": {"type": "ggx", "alpha": ALPHA, "f0": [0.9, 0.9, 0.9], "f82": [0.9, 0.9, 0.9]}},
        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    }
    if realref:
        scene["environment"] = {"constant": [0.3, 0.3, 0.3]}
        scene["lights"] = [{"type": "directional", "direction": list(SUN), "irradiance": [3, 3, 3]}]
        scene["materials"]["m"] = {"type": "ggx", "alpha": REALREF_ALPHA, "f0": [1, 1, 1], "f82": [1, 1, 1]}
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    times = []
    for _ in range(RUNS):
        out = subprocess.run([binary, "render", path, "-o", os.path.join(work, "facetfit.exr")], check=True,
                             capture_output=True, text=True).stdout
        times.append(float(re.search(r"spp, ([0-9.]+) s\)", out).group(1)))
    return sky, times


def cycles_times(sky, work, adaptive=False, realref=False):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SPP
    scene.cycles.use_adaptive_sampling = adaptive
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 1  # direct lighting, as the reference renderer
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "AUTO"
    scene.render.filepath = os.path.join(work, "cycles.exr")
    scene.render.image_settings.file_format = "OPEN_EXR"
    # Blender is z-up: facetfit's (x, y, z) is Blender's (x, -z, y).
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0, location=(0, 0, 0))
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.active_object
    mat = bpy.data.materials.new("ggx")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    alpha = REALREF_ALPHA if realref else ALPHA
    glossy.inputs["Roughness"].default_value = math.sqrt(alpha)  # Blender's alpha = roughness^2
    glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0) if realref else (0.9, 0.9, 0.9, 1.0)
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(glossy.outputs["BSDF"], out.inputs["Surface"])
    sphere.data.materials.append(mat)
    bpy.ops.object.camera_add(location=(0, -4, 0.6))
    cam = bpy.context.active_object
    direction = -cam.location
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle_y = math.radians(30)
    scene.camera = cam
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    if realref:
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
        # A sun of irradiance 3 shining along -SUN: Blender's (x, -z, y) of facetfit's vector, its -Z axis along the light.
        sun = bpy.data.lights.new("sun", "SUN")
        sun.energy = 3.0
        sun.angle = 0.0  # a directional light, as the reference renderer's
        lamp = bpy.data.objects.new("sun", sun)
        bpy.context.collection.objects.link(lamp)
        toward = mathutils.Vector((SUN[0], -SUN[2], SUN[1])).normalized()
        lamp.rotation_euler = (-toward).to_track_quat("-Z", "Y").to_euler()
    else:
        env = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        env.image = bpy.data.images.load(sky)
        world.node_tree.links.new(env.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
    scene.world = world
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        times.append(time.perf_counter() - start)
    return times


def main():
    binary, output = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as work:
        sky, ours = facetfit_times(binary, work)
        cycles = cycles_times(sky, work)
        cycles_adaptive = cycles_times(sky, work, adaptive=True)
        _, ours_realref = facetfit_times(binary, work, realref=True)
        cycles_realref = cycles_times(sky, work, realref=True)
    a, b, c = statistics.median(ours), statistics.median(cycles), statistics.median(cycles_adaptive)
    d, e = statistics.median(ours_realref), statistics.median(cycles_realref)
    text = "\n".join([
        "# Reference renderer against Cycles",
        "",
        "Generated by `make bench` (scripts/cycles_compare.py); do not edit by hand.",
        "",
        f"Same run, same machine ({os.cpu_count()} cores, both renderers on all of them): a GGX sphere (alpha {ALPHA},",
        f"Blender roughness {math.sqrt(ALPHA):.3f}) under the built-in sky as a lat-long EXR, {SIZE} x {SIZE}, {SPP} spp,",
        "direct lighting (Cycles: max bounces 1, no denoising, no adaptive sampling; Blender " + bpy.app.version_string + ").",
        f"Median of {RUNS} renders; each time covers scene setup, acceleration structure and rendering.",
        "",
        "| renderer | seconds (median) | runs |",
        "|---|---|---|",
        f"| facetfit (MIS) | {a:.2f} | {', '.join(f'{t:.2f}' for t in ours)} |",
        f"| Cycles (bpy), 64 spp everywhere | {b:.2f} | {', '.join(f'{t:.2f}' for t in cycles)} |",
        f"| Cycles (bpy), adaptive sampling on (its default; fewer samples where it converges) | {c:.2f} | {', '.join(f'{t:.2f}' for t in cycles_adaptive)} |",
        "",
        f"Cycles with the same samples takes {b / a:.2f} x facetfit's time; with adaptive sampling {c / a:.2f} x.",
        "",
        f"The scene of docs/render-speed.md (../shared/data/realref: constant environment 0.3, a directional light of",
        f"irradiance 3, GGX alpha {REALREF_ALPHA} with F = 1; Blender's sun of angle 0), same size and samples:",
        "",
        "| renderer | seconds (median) | runs |",
        "|---|---|---|",
        f"| facetfit (MIS) | {d:.2f} | {', '.join(f'{t:.2f}' for t in ours_realref)} |",
        f"| Cycles (bpy), 64 spp everywhere | {e:.2f} | {', '.join(f'{t:.2f}' for t in cycles_realref)} |",
        "",
        f"Cycles takes {e / d:.2f} x facetfit's time there (Mitsuba 3's times on this scene: render-speed.md).",
        "",
    ])
    tmp = output + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, output)
    print(text)


if __name__ == "__main__":
    main()
