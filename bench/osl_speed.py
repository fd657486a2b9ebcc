"""The production material's cost in Cycles, side by side with Cycles' own Principled BSDF and with MaterialX's
OSL of the same closures, in one process (docs/osl.md, "Cost"). Run with the bpy venv's python (bench/osl_speed.sh
prepares the LUT and the MaterialX shader):

    python osl_speed.py LUT.exr MATERIALX.osl OUT_DIR [RUNS]

The realref scene (a unit sphere, a constant environment of 0.3 and a sun of irradiance 3 toward (0.3, 1, 0.5),
../shared/data/realref), 256 x 256, 64 samples per pixel, direct lighting, CPU, Cycles' OSL shading system for all
three. Each material renders once to compile, then RUNS times; the median of those is its time. Prints a
Markdown table and writes OUT_DIR/NAME.exr of each material's last render.
"""
import os
import statistics
import sys
import time

# The tests' Cycles scene (tests/osl/cycles_render.py, which also puts bpy's own oslquery on the path): one
# realref scene for the tests and this benchmark.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "osl"))
import cycles_render  # noqa: E402
import bpy  # noqa: E402  Blender as a Python module (bpy wheel)

SIZE, SPP = 256, 64


def scene_setup():
    scene = cycles_render.new_scene(SIZE, SPP)  # OSL for all three, direct lighting, box filter
    sphere = cycles_render.sphere_and_camera(scene)
    cycles_render.realref_lighting(scene)
    return scene, sphere


def material_of(kind, lut, materialx_osl):
    material = bpy.data.materials.new(kind)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    if kind == "principled":
        bsdf = nodes.new("ShaderNodeBsdfPrincipled")
        bsdf.inputs["Base Color"].default_value = (0.6, 0.3, 0.2, 1)
        bsdf.inputs["Roughness"].default_value = 0.3
        material.node_tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
        return material
    script = nodes.new("ShaderNodeScript")
    script.mode = "EXTERNAL"
    script.filepath = materialx_osl if kind == "materialx" else os.path.join(os.path.dirname(__file__), "..", "osl",
                                                                             "facetfit_material.osl")
    script.update()
    if not script.outputs:
        sys.exit(f"{script.filepath}: did not compile")
    if kind == "facetfit":
        script.inputs["lut"].default_value = lut
    material.node_tree.links.new(script.outputs[0], output.inputs["Surface"])
    return material


def main(lut, materialx_osl, out_dir, runs):
    scene, sphere = scene_setup()
    rows = []
    for kind in ("principled", "facetfit", "materialx"):
        sphere.data.materials.clear()
        sphere.data.materials.append(material_of(kind, lut, materialx_osl))
        scene.render.filepath = os.path.join(out_dir, kind + ".exr")
        times = []
        for run in range(runs + 1):  # the first compiles
            start = time.perf_counter()
            bpy.ops.render.render(write_still=run == runs)
            times.append(time.perf_counter() - start)
        rows.append((kind, statistics.median(times[1:]), times[0]))
    base = rows[0][1]
    mx = rows[2][1]
    print("| material | seconds (median of %d) | first render | against Principled | against MaterialX's OSL |" % runs)
    print("|---|---|---|---|---|")
    for kind, seconds, first in rows:
        print("| %s | %.2f | %.2f | %.2fx | %.2fx |" % (kind, seconds, first, seconds / base, seconds / mx))


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3]),
         int(sys.argv[4]) if len(sys.argv) > 4 else 3)
