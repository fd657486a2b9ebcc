#!/usr/bin/env python3
"""Commands that meet only OpenEXR files do not load OpenImageIO; one that writes a PNG does.

usage: libraries.py FACETFIT

OpenImageIO brings ~260 shared libraries (0.3 s of every start before it left the common path:
lib/io/image_file.h); this fails if a change links it back into the command plugin or reads an EXR
through it. What is loaded is read from the dynamic loader itself (LD_DEBUG=libs).
"""
import json
import os
import subprocess
import sys
import tempfile


def loads_openimageio(facetfit, args):
    run = subprocess.run([facetfit, "-q"] + args, env=dict(os.environ, LD_DEBUG="libs"), capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("facetfit %s failed (%d): %s" % (" ".join(args), run.returncode, run.stderr[-2000:]))
    return "libOpenImageIO" in run.stderr


def main(facetfit):
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "scene.json")
        with open(scene, "w") as f:
            json.dump({"camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30, "width": 8, "height": 8},
                       "render": {"spp": 1, "seed": 1}, "environment": {"constant": [0.3, 0.3, 0.3]},
                       "materials": {"m": {"type": "lut", "file": os.path.join(tmp, "gold-ggx-0.15.exr")}},
                       "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]}, f)
        cases = [
            (["bake", "builtin:gold-ggx-0.15", "-o", tmp], False),
            (["info", os.path.join(tmp, "gold-ggx-0.15.exr")], False),
            (["render", scene, "-o", os.path.join(tmp, "a.exr")], False),
            (["diff", os.path.join(tmp, "a.exr"), os.path.join(tmp, "a.exr")], False),
            (["render", scene, "-o", os.path.join(tmp, "b.exr"), "--png", os.path.join(tmp, "b.png")], True),
        ]
        failures = []
        for args, expected in cases:
            got = loads_openimageio(facetfit, args)
            print("%-6s %s: OpenImageIO %s" % ("ok" if got == expected else "FAIL", " ".join(args[:1]) + (" --png" if "--png" in args else ""),
                                               "loaded" if got else "not loaded"))
            if got != expected:
                failures.append(args[0])
        if failures:
            sys.exit("OpenImageIO loaded where it should not be, or not where it should: " + ", ".join(failures))


if __name__ == "__main__":
    main(sys.argv[1])
