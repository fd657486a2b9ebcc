"""Smoke test of the OSL shaders in Cycles (bpy wheel): renders a sphere with the material shader (a LUT,
then a missing LUT: the error colour, not magenta) and with the preview shader, and prints the centre
pixels. Groundwork for the OSL test suite (issue 5). Usage:
    python osl_smoke.py LUT.exr SKY.exr OUT_FOLDER
"""
import glob
import os
import sys

import bpy
import numpy as np

# OpenImageIO's module and oslquery (which Cycles needs for script nodes) ship inside bpy's own tree.
sys.path += glob.glob(os.path.join(sys.prefix, "lib", "python3*", "site-packages", "bpy", "*", "python", "lib", "python3*", "site-packages"))
OSL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "osl")
lut, sky, out = sys.argv[1], sys.argv[2], sys.argv[3]
def render(shader_file, params, name):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "CYCLES"; s.cycles.device = "CPU"; s.cycles.shading_system = True
    s.cycles.samples = 8; s.cycles.use_denoising = False
    s.render.resolution_x = s.render.resolution_y = 48
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32); bpy.ops.object.shade_smooth()
    sph = bpy.context.active_object
    m = bpy.data.materials.new("m"); m.use_nodes = True; nt = m.node_tree; nt.nodes.clear()
    sc = nt.nodes.new("ShaderNodeScript"); sc.mode = "EXTERNAL"; sc.filepath = shader_file
    sc.update()
    for k, v in params.items(): sc.inputs[k].default_value = v
    o = nt.nodes.new("ShaderNodeOutputMaterial"); nt.links.new(sc.outputs[0], o.inputs["Surface"])
    sph.data.materials.append(m)
    bpy.ops.object.camera_add(location=(0, -4, 0.6)); cam = bpy.context.active_object
    cam.rotation_euler = (-cam.location).to_track_quat("-Z", "Y").to_euler(); s.camera = cam
    w = bpy.data.worlds.new("w"); w.use_nodes = True
    env = w.node_tree.nodes.new("ShaderNodeTexEnvironment"); env.image = bpy.data.images.load(sky)
    w.node_tree.links.new(env.outputs["Color"], w.node_tree.nodes["Background"].inputs["Color"]); s.world = w
    s.render.filepath = out + "/" + name + ".png"; bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(s.render.filepath); px = np.array(img.pixels[:]).reshape(48, 48, 4)
    c = px[24, 24, :3]; print(name, "centre pixel", np.round(c, 3), "inputs", [i.name for i in sc.inputs])
render(os.path.join(OSL, "facetfit_material.osl"), {"lut": lut}, "material")
render(os.path.join(OSL, "facetfit_material.osl"), {"lut": "/nonexistent.exr"}, "missing")
render(os.path.join(OSL, "facetfit_preview.osl"), {"lut": lut, "environment_map": sky, "samples": 16}, "preview")
