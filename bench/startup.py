#!/usr/bin/env python3
"""Whole-process wall time and peak memory of facetfit commands (make bench; docs/benchmarks.md).

usage: startup.py FACETFIT OUT.md [RUNS] [RGL_FILE]

Each command runs RUNS times under /usr/bin/time; the table gives the median wall time (by the clock,
around the whole run) and the median of the peak resident set sizes. The MERL file is written by facetfit itself (builtin:red-plastic);
with RGL_FILE, one real RGL material is fitted and re-baked from the cache as whole processes on one thread.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def measure(cmd, runs):
    walls, rss = [], []
    for _ in range(runs):
        # Wall time by the clock around the whole run (/usr/bin/time's %e has 10 ms steps), peak memory
        # from /usr/bin/time's %M.
        start = time.perf_counter()
        out = subprocess.run(["/usr/bin/time", "-f", "%M"] + cmd, stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True, check=True)
        walls.append((time.perf_counter() - start) * 1e3)
        rss.append(float(out.stderr.strip().splitlines()[-1]) / 1024.0)
    return statistics.median(walls), statistics.median(rss)


def main(facetfit, dst, runs=10, rgl=None):
    with tempfile.TemporaryDirectory() as tmp:
        merl = os.path.join(tmp, "red-plastic.binary")
        subprocess.run([facetfit, "convert", "builtin:red-plastic", "-o", merl], check=True, stdout=subprocess.DEVNULL)
        subprocess.run([facetfit, "-q", "bake", "builtin:red-plastic", "-o", tmp], check=True, stdout=subprocess.DEVNULL)
        lut = os.path.join(tmp, "red-plastic.exr")
        # bench/render_compare.py's scene (GGX 0.3 sphere, constant environment, one light) at 8 x 8, 1 spp.
        scene = os.path.join(tmp, "scene.json")
        with open(scene, "w") as f:
            json.dump({"camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30, "width": 8, "height": 8},
                       "render": {"spp": 1, "seed": 1}, "environment": {"constant": [0.3, 0.3, 0.3]},
                       "lights": [{"type": "directional", "direction": [0.3, 1, 0.5], "irradiance": [3, 3, 3]}],
                       "materials": {"m": {"type": "ggx", "alpha": 0.3, "f0": [1, 1, 1], "f82": [1, 1, 1], "smith": "separable"}},
                       "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]}, f)
        render = [facetfit, "-q", "render", scene, "-o", os.path.join(tmp, "x.exr")]
        cases = [
            ("`facetfit fit FILE --refine none` (the paper's method: the reference program's job)", [facetfit, "fit", merl, "--refine", "none"]),
            ("`facetfit fit FILE` (default: refinement and parametric fits)", [facetfit, "fit", merl]),
            ("`facetfit --version`", [facetfit, "--version"]),
            ("`facetfit bake --help` (loads the command plugin: OpenEXR, OpenColorIO, Embree)", [facetfit, "bake", "--help"]),
            ("`facetfit info LUT.exr` (the plugin; the LUT through OpenEXR)", [facetfit, "info", lut]),
            ("`facetfit render SCENE -o X.exr`: bench/render_compare.py's GGX sphere at 8 x 8, 1 spp (start-up alone)", render),
            ("the same render `--png X.png` (also loads facetfit-oiio.so: OpenImageIO)", render + ["--png", os.path.join(tmp, "x.png")]),
        ]
        if rgl and os.path.exists(rgl):
            name = os.path.basename(rgl)
            luts = os.path.join(tmp, "rgl-luts")
            bake = [facetfit, "-q", "--threads", "1", "bake", rgl, "-o", luts]
            subprocess.run(bake, check=True, stdout=subprocess.DEVNULL)  # the cache the re-bake reads
            cases += [
                (f"`facetfit --threads 1 fit {name}` (a real RGL file: load, refinement, parametric and closure fits)",
                 [facetfit, "--threads", "1", "fit", rgl]),
                (f"`facetfit --threads 1 fit {name} --refine none`", [facetfit, "--threads", "1", "fit", rgl, "--refine", "none"]),
                (f"`facetfit --threads 1 bake {name}` again (cached: its hash and sidecar checked, nothing fitted)", bake),
            ]
        lines = ["| command | wall (median) | peak memory (median) |", "|---|---|---|"]
        for what, cmd in cases:
            wall, rss = measure(cmd, runs)
            lines.append(f"| {what} | {wall:.0f} ms | {rss:.0f} MiB |")
    with open(dst, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 10, sys.argv[4] if len(sys.argv) > 4 else None)
