"""Renders with Blender's Cycles (bpy wheel, OSL on the CPU) for tests/osl/test_osl_*.cpp and docs/osl.md.

    python cycles_render.py probe SHADER OUT.exr SIZE [NAME=VALUE ...]
        An orthographic view of the plane [-1, 1]^2 at z = 0, SIZE x SIZE pixels, one sample per pixel at
        its centre: each pixel shows the shader's emission at that pixel (tests/osl/facetfit_probe.osl).
    python cycles_render.py sphere SHADER OUT.exr SIZE SPP ENV.exr [NAME=VALUE ...]
        The reference renderer's default view (docs/scene-format.md) of a unit sphere shaded by SHADER
        under the lat-long map ENV.exr, direct lighting, box pixel filter, transparent film.
    python cycles_render.py batch JOBS.json
        Several renders in one Blender process (its start-up is most of a small render's time): JOBS.json is
        a list of {"command": "sphere" or "sun", "shader", "out", "size", "spp", "environment" (sphere),
        "params": {NAME: VALUE}}. "sun" is the same view of the sphere under a constant world of 0.3 and a sun
        lamp of strength 3 toward facetfit's (0.3, 1, 0.5): the scene of ../shared/data/realref.

NAME=VALUE set the shader's parameters (ints, floats, strings, or vectors as x,y,z, as the parameter's type).
stretch_texture=IMAGE (sphere only) drives roughness_scale_x and roughness_scale_y by the image's R and G times
their given values, through Blender's Image Texture node (sphere projection of the generated coordinates,
linear interpolation, repeat), as an artist would connect a roughness texture. Output: float RGBA OpenEXR,
scene-linear, no view transform.
"""
import glob
import math
import os
import sys

# OpenImageIO's module and oslquery, which script nodes need, ship inside bpy's own tree.
sys.path += glob.glob(os.path.join(sys.prefix, "lib", "python3*", "site-packages", "bpy", "*", "python", "lib",
                                   "python3*", "site-packages"))
import bpy  # noqa: E402


def new_scene(size, spp):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.shading_system = True  # OSL
    scene.cycles.samples = spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 1  # direct lighting, as the reference renderer
    scene.cycles.pixel_filter_type = "BOX"
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGBA"
    return scene


def script_material(shader, params):
    material = bpy.data.materials.new("facetfit")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    script = nodes.new("ShaderNodeScript")
    script.mode = "EXTERNAL"
    script.filepath = os.path.abspath(shader)
    script.update()
    if not script.outputs:
        sys.exit(f"{shader}: the script node has no outputs (the shader did not compile)")
    for name, text in params.items():
        if name not in script.inputs:
            sys.exit(f"{shader}: no parameter '{name}' (has {[i.name for i in script.inputs]})")
        socket = script.inputs[name]
        value = socket.default_value
        if isinstance(value, (int, float, str)):
            socket.default_value = type(value)(text)
        else:  # a vector or colour: "x,y,z"
            socket.default_value = [float(v) for v in text.split(",")]
    out = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(script.outputs[0], out.inputs["Surface"])
    return material


def connect_stretch_texture(material, image):
    """The image's R and G times the script node's roughness_scale_x and _y, into those inputs."""
    tree = material.node_tree
    script = next(n for n in tree.nodes if n.type == "SCRIPT")
    coords = tree.nodes.new("ShaderNodeTexCoord")
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(os.path.abspath(image))
    texture.image.colorspace_settings.name = "Non-Color"
    texture.projection = "SPHERE"
    texture.interpolation = "Linear"
    texture.extension = "REPEAT"
    tree.links.new(coords.outputs["Generated"], texture.inputs["Vector"])
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    tree.links.new(texture.outputs["Color"], separate.inputs["Color"])
    for channel, name in (("Red", "roughness_scale_x"), ("Green", "roughness_scale_y")):
        scale = tree.nodes.new("ShaderNodeMath")
        scale.operation = "MULTIPLY"
        tree.links.new(separate.outputs[channel], scale.inputs[0])
        scale.inputs[1].default_value = script.inputs[name].default_value
        tree.links.new(scale.outputs["Value"], script.inputs[name])


def render(scene, out):
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    if not os.path.exists(out):
        sys.exit(f"{out}: Cycles wrote no image")


def probe(shader, out, size, params):
    scene = new_scene(size, 1)
    scene.cycles.filter_width = 0.01  # one sample at each pixel's centre, no neighbour bleeding in
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    bpy.context.active_object.data.materials.append(script_material(shader, params))
    bpy.ops.object.camera_add(location=(0, 0, 1), rotation=(0, 0, 0))
    camera = bpy.context.active_object
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2.0
    scene.camera = camera
    render(scene, out)


def sphere_and_camera(scene):
    """The unit sphere and the reference renderer's default camera, added to SCENE; returns the sphere."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=1.0)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.active_object
    # Blender is z-up: facetfit's (x, y, z) is Blender's (x, z, -y) read backwards, i.e. Blender (x, y, z)
    # = facetfit (x, -z, y). The camera at facetfit (0, 0.6, 4) looking at the origin.
    bpy.ops.object.camera_add(location=(0, -4, 0.6))
    camera = bpy.context.active_object
    camera.rotation_euler = (-camera.location).to_track_quat("-Z", "Y").to_euler()
    camera.data.sensor_fit = "VERTICAL"
    camera.data.angle_y = math.radians(30)
    scene.camera = camera
    return sphere


def realref_lighting(scene):
    """The lights of ../shared/data/realref in SCENE: a constant world of 0.3 and a sun lamp of strength 3
    toward facetfit's (0.3, 1, 0.5)."""
    from mathutils import Vector
    world = bpy.data.worlds.new("constant")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.3, 0.3, 0.3, 1)
    scene.world = world
    lamp = bpy.data.lights.new("sun", "SUN")
    lamp.energy = 3.0
    lamp.angle = 0.0
    lamp_object = bpy.data.objects.new("sun", lamp)
    toward = Vector((0.3, -0.5, 1.0)).normalized()  # facetfit's (0.3, 1, 0.5) in Blender's frame
    lamp_object.rotation_euler = toward.to_track_quat("Z", "Y").to_euler()  # the lamp shines along its -Z
    scene.collection.objects.link(lamp_object)


def shaded_sphere(shader, size, spp, params):
    """A new scene of the unit sphere shaded by SHADER, seen from the reference renderer's default camera."""
    scene = new_scene(size, spp)
    sphere = sphere_and_camera(scene)
    stretch_texture = params.pop("stretch_texture", None)
    material = script_material(shader, params)
    if stretch_texture:
        connect_stretch_texture(material, stretch_texture)
    sphere.data.materials.append(material)
    return scene


def sphere(shader, out, size, spp, environment, params):
    scene = shaded_sphere(shader, size, spp, params)
    world = bpy.data.worlds.new("environment")
    world.use_nodes = True
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(os.path.abspath(environment))
    texture.image.colorspace_settings.name = "Linear Rec.709"
    texture.interpolation = "Closest"  # the reference renderer reads one pixel per direction
    # Blender's lat-long u is 1/2 - atan2(y, x) / 2 pi; facetfit's, (atan2(x, -z) + pi) / 2 pi in its own
    # frame, is that plus 1/4: the lookup direction turns a quarter turn clockwise about z.
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "VECTOR"
    mapping.inputs["Rotation"].default_value = (0, 0, -math.pi / 2)
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    tree.links.new(texture.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    scene.world = world
    render(scene, out)


def sun(shader, out, size, spp, params):
    scene = shaded_sphere(shader, size, spp, params)
    realref_lighting(scene)
    render(scene, out)


def batch(path):
    import json
    with open(path) as f:
        jobs = json.load(f)
    for job in jobs:
        params = {k: str(v) for k, v in job.get("params", {}).items()}
        if job["command"] == "sphere":
            sphere(job["shader"], job["out"], int(job["size"]), int(job["spp"]), job["environment"], params)
        elif job["command"] == "sun":
            sun(job["shader"], job["out"], int(job["size"]), int(job["spp"]), params)
        else:
            sys.exit(f"{path}: unknown command {job['command']}")


def main(argv):
    if len(argv) == 3 and argv[1] == "batch":
        return batch(argv[2])
    if len(argv) < 5:
        sys.exit(__doc__)
    command, shader, out, size = argv[1], argv[2], argv[3], int(argv[4])
    rest = argv[5:]
    if command == "probe":
        probe(shader, out, size, dict(a.split("=", 1) for a in rest))
    elif command == "sphere":
        sphere(shader, out, size, int(rest[0]), rest[1], dict(a.split("=", 1) for a in rest[2:]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
