#!/usr/bin/env python3
"""facetfit's renderer against Mitsuba 3 on the same scene (make bench; docs/render-speed.md).

usage: render_compare.py FACETFIT MITSUBA_PYTHON OUT.md [RGL_FILE]

The scene of ../shared/data/realref (a unit sphere seen from (0, 0.6, 4), vertical field of view 30
degrees, constant environment 0.3, one directional light of irradiance 3 toward (0.3, 1, 0.5), direct
lighting) at 256 x 256, 64 and 1024 samples per pixel, both renderers on every core. Spheres: GGX
alpha 0.3 with F = 1 and separable Smith masking (Mitsuba's roughconductor with material none, sampling
visible normals), a facetfit LUT of GGX 0.3 (Mitsuba cannot read it: compared with its GGX time), a
measured MERL table (facetfit's writer, builtin:gold-ggx-0.15; Mitsuba 3 has no MERL reader: compared
with its GGX time) and a measured RGL file (Mitsuba's `measured` plugin, the format authors' own).

Two times per renderer: one render (facetfit: the time it prints, which covers loading the material,
building the scene and rendering; Mitsuba: the second render in its process, after its kernels are
compiled and with the scene loaded) and the whole process from launch to exit (Mitsuba llvm_ad_rgb: with
its kernel cache warm, the second process). Median of RUNS, facetfit's runs in turn with Mitsuba
llvm_ad_rgb's (a shared machine's load changes from minute to minute). Mitsuba's llvm_ad_rgb variant needs LLVM >= 16:
Debian's libllvm19, through DRJIT_LIBLLVM_PATH; without it that column says so.
"""
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

SIZE, RUNS = 256, 3
SPPS = (64, 1024)
LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"

# The Mitsuba side, run in the Mitsuba venv's python as its own process: VARIANT SPP MATERIAL_JSON RENDERS
# (2 to time the second render; 1 for the whole process of one render).
MITSUBA_SCRIPT = r"""
import json, os, sys, time
import mitsuba as mi
variant, spp, material, renders = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3]), int(sys.argv[4])
images = sys.argv[5] if len(sys.argv) > 5 else None  # where to write each render (a %%d for its seed), untimed
mi.set_variant(variant)
if os.environ.get("FACETFIT_LLVM_TARGET"):
    # CPU:FEATURES:WIDTH for Dr.Jit's LLVM back end (jit_llvm_set_target in drjit-core's jit.h, exported with
    # C++ linkage by this wheel), before any kernel compiles: the vector width Mitsuba's kernels get.
    import ctypes, drjit
    core = ctypes.CDLL(os.path.join(os.path.dirname(drjit.__file__), "libdrjit-core.so"))
    set_target = getattr(core, "_Z19jit_llvm_set_targetPKcS0_j")
    cpu, features, width = os.environ["FACETFIT_LLVM_TARGET"].split(":")
    set_target(cpu.encode(), features.encode(), ctypes.c_uint32(int(width)))
T = mi.ScalarTransform4f
if material["type"] == "ggx":
    bsdf = {"type": "roughconductor", "distribution": "ggx", "alpha": material["alpha"], "material": "none",
            "sample_visible": True}
else:
    bsdf = {"type": "measured", "filename": material["file"]}
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "direct"},
    "sensor": {"type": "perspective", "fov": 30, "fov_axis": "y",
               "to_world": T().look_at(origin=[0, 0.6, 4], target=[0, 0, 0], up=[0, 1, 0]),
               "film": {"type": "hdrfilm", "width": %(size)d, "height": %(size)d, "rfilter": {"type": "box"}},
               "sampler": {"type": "independent", "sample_count": spp}},
    "sphere": {"type": "sphere", "center": [0, 0, 0], "radius": 1, "bsdf": bsdf},
    "env": {"type": "constant", "radiance": {"type": "rgb", "value": 0.3}},
    "sun": {"type": "directional", "direction": [-0.3, -1, -0.5], "irradiance": {"type": "rgb", "value": 3}},
})
times = []
for seed in range(renders):
    start = time.perf_counter()
    image = mi.render(scene, spp=spp, seed=seed)
    mi.Bitmap(image)  # forces the evaluation of the JIT variant
    times.append(time.perf_counter() - start)
    if images:
        mi.Bitmap(image).write(images %% seed)
print("\nfacetfit-times " + json.dumps(times))  # Mitsuba leaves its loading line unterminated
""" % {"size": SIZE}


# Per-pixel noise from two renders of each renderer with different seeds, in the Mitsuba venv's python
# (numpy, OpenEXR through mi.Bitmap): FACETFIT_A FACETFIT_B MITSUBA_A MITSUBA_B. Over the pixels the sphere
# covers wholly (facetfit's alpha 1): the variance of one render, E[(a - b)^2] / 2 over pixels and channels,
# and the mean, which two unbiased renderers share.
NOISE_SCRIPT = r"""
import json, sys
import numpy as np
import mitsuba as mi
mi.set_variant("scalar_rgb")
ff_a, ff_b, mi_a, mi_b = [np.array(mi.Bitmap(p), dtype=np.float64) for p in sys.argv[1:5]]
inside = ff_a[..., 3] > 0.999
out = {"pixels": int(inside.sum())}
for name, a, b in (("facetfit", ff_a, ff_b), ("mitsuba", mi_a, mi_b)):
    a, b = a[..., :3][inside], b[..., :3][inside]
    out[name] = {"variance": float(np.mean((a - b) ** 2) / 2), "mean": float(np.mean(a + b) / 2)}
print("\nfacetfit-noise " + json.dumps(out))
"""


def runs_at(spp):
    """Repetitions: RUNS at 64 spp; one at 1024, where a run lasts seconds and varies by a few percent."""
    return RUNS if spp <= 64 else 1


def median(xs):
    return statistics.median(xs)


def write_scene(work, material, spp, environment=True, light=True, seed=1):
    """The scene in facetfit's format, as work/scene.json; without the environment or the light where told."""
    scene = {
        "camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30, "width": SIZE, "height": SIZE},
        "render": {"spp": spp, "seed": seed},
        "lights": [{"type": "directional", "direction": [0.3, 1, 0.5], "irradiance": [3, 3, 3]}] if light else [],
        "materials": {"m": material},
        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    }
    if environment:
        scene["environment"] = {"constant": [0.3, 0.3, 0.3]}
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


def medians(runs):
    """Per field, the median over runs of equal tuples."""
    return tuple(median([run[i] for run in runs]) for i in range(len(runs[0])))


def facetfit_once(binary, work, path, prefix=()):
    """One facetfit render of the scene file: (render time it prints, whole process, peak memory in MiB)."""
    start = time.perf_counter()
    run = subprocess.run(list(prefix) + ["/usr/bin/time", "-f", "%M", binary, "render", path, "-o", os.path.join(work, "facetfit.exr")],
                         check=True, capture_output=True, text=True)
    process = time.perf_counter() - start
    return (float(re.search(r"spp, ([0-9.]+) s\)", run.stdout).group(1)), process, float(run.stderr.strip().splitlines()[-1]) / 1024.0)


def facetfit_run(binary, work, material, spp, prefix=(), environment=True, light=True):
    """(render time it prints, whole process, peak memory in MiB), medians; without the environment or the
    light where told (the stages of docs/render-speed.md)."""
    path = write_scene(work, material, spp, environment, light)
    return medians([facetfit_once(binary, work, path, prefix) for _ in range(runs_at(spp))])


def mitsuba_launch(python, variant, material, spp, env, prefix, renders):
    """One Mitsuba process rendering `renders` times: (its render times, wall time, peak memory in MiB)."""
    start = time.perf_counter()
    out = subprocess.run(list(prefix) + ["/usr/bin/time", "-f", "%M", python, "-c", MITSUBA_SCRIPT, variant, str(spp),
                          json.dumps(material), str(renders)], check=True, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    return json.loads(out.stdout.split("facetfit-times ")[-1]), wall, float(out.stderr.strip().splitlines()[-1]) / 1024.0


def mitsuba_once(python, variant, material, spp, env, prefix=()):
    """(second render's time, whole process of one render, its peak memory in MiB)."""
    second = mitsuba_launch(python, variant, material, spp, env, prefix, 2)[0][1]
    _, wall, mib = mitsuba_launch(python, variant, material, spp, env, prefix, 1)
    return second, wall, mib


def mitsuba_run(python, variant, material, spp, env, prefix=()):
    """mitsuba_once's figures, medians, after a launch that warms the kernel cache."""
    mitsuba_launch(python, variant, material, spp, env, prefix, 1)
    return medians([mitsuba_once(python, variant, material, spp, env, prefix) for _ in range(runs_at(spp))])


def side_by_side(facetfit, work, ff_material, python, mi_material, spp, env):
    """facetfit_run's and mitsuba_run's (llvm_ad_rgb) figures from runs taken in turn, so that both renderers
    meet the same load on a shared machine."""
    path = write_scene(work, ff_material, spp)
    mitsuba_launch(python, "llvm_ad_rgb", mi_material, spp, env, (), 1)
    ff, mi = [], []
    for _ in range(runs_at(spp)):
        ff.append(facetfit_once(facetfit, work, path))
        mi.append(mitsuba_once(python, "llvm_ad_rgb", mi_material, spp, env))
    return medians(ff), medians(mi)


def noise(facetfit, python, work, ff_material, mi_material, spp, env, variant):
    """Both renderers' per-pixel noise and mean on one sphere (NOISE_SCRIPT), two seeds each."""
    images = []
    for seed in (1, 2):
        images.append(os.path.join(work, "noise-facetfit-%d.exr" % seed))
        subprocess.run([facetfit, "render", write_scene(work, ff_material, spp, seed=seed), "-o", images[-1]], check=True,
                       capture_output=True)
    pattern = os.path.join(work, "noise-mitsuba-%d.exr")
    subprocess.run([python, "-c", MITSUBA_SCRIPT, variant, str(spp), json.dumps(mi_material), "2", pattern], check=True,
                   capture_output=True, env=env)
    out = subprocess.run([python, "-c", NOISE_SCRIPT] + images + [pattern % 0, pattern % 1], check=True, capture_output=True,
                         text=True, env=env).stdout
    return json.loads(out.split("facetfit-noise ")[-1])


def profile(binary, work, material):
    """The hottest symbols of one facetfit render (64 spp) under linux-perf: [(percent, library, symbol)]."""
    facetfit_run(binary, work, material, 64)  # writes scene.json
    data = os.path.join(work, "perf.data")
    try:
        subprocess.run(["perf", "record", "-o", data, binary, "render", os.path.join(work, "scene.json"), "-o",
                        os.path.join(work, "profile.exr")], check=True, capture_output=True)
        out = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "dso,symbol", "--stdio"],
                             check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return [], []
    rows = []
    for line in out.splitlines():
        m = re.match(r"\s+([0-9.]+)%\s+(\S+)\s+\[[.k]\]\s+(.*)", line)
        if m:
            symbol = m.group(3).strip()
            while re.search(r"\([^()]*\)", symbol):  # no argument lists: render's lambdas keep their names
                symbol = re.sub(r"\([^()]*\)", "", symbol)
            rows.append((float(m.group(1)), m.group(2), re.sub(r"\s+-\s+-\s*$", "", symbol).strip()[:80]))
    libraries = {}
    for pct, dso, _ in rows:
        libraries[dso] = libraries.get(dso, 0.0) + pct
    return rows[:14], sorted(libraries.items(), key=lambda kv: -kv[1])[:5]


def start_up(binary):
    """(median process time of `render --help`, shared libraries of the command plugin, share of the time in
    the dynamic loader as text)."""
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        subprocess.run([binary, "render", "--help"], check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    plugin = os.path.join(os.path.dirname(os.path.abspath(binary)), "facetfit-commands.so")
    libraries = subprocess.run(["ldd", plugin], capture_output=True, text=True).stdout.count("=>")
    share = "n/a"
    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "perf.data")
        if subprocess.run(["perf", "record", "-q", "-o", data, binary, "render", "--help"], capture_output=True).returncode == 0:
            out = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "dso", "--stdio"],
                                 capture_output=True, text=True).stdout
            for line in out.splitlines():
                m = re.match(r"\s*([0-9.]+)%\s+(\S+)", line)
                if m and m.group(2).startswith("ld-linux"):
                    share = "%.0f%%" % float(m.group(1))
    return median(times), libraries, share


def main(facetfit, mitsuba_python, dst, rgl=None):
    work = tempfile.mkdtemp()
    env = dict(os.environ)
    llvm = os.path.exists(LLVM)
    if llvm:
        env["DRJIT_LIBLLVM_PATH"] = LLVM
    merl = os.path.join(work, "gold.binary")
    lut_dir = os.path.join(work, "luts")
    subprocess.run([facetfit, "convert", "builtin:gold-ggx-0.15", "-o", merl], check=True, capture_output=True)
    ggx_ff = {"type": "ggx", "alpha": 0.3, "f0": [1, 1, 1], "f82": [1, 1, 1], "smith": "separable"}
    ggx_mi = {"type": "ggx", "alpha": 0.3}
    # The LUT sphere: GGX 0.3 with F = 1 and separable masking, through facetfit's own MERL writer and bake.
    subprocess.run([facetfit, "bake", merl, "-o", lut_dir, "--smith", "separable"], check=True, capture_output=True)
    cases = [("GGX 0.3", ggx_ff, ggx_mi), ("tabulated LUT (gold)", {"type": "lut", "file": os.path.join(lut_dir, "gold.exr")}, ggx_mi),
             ("measured MERL (gold)", {"type": "measured", "file": merl, "proposal": os.path.join(lut_dir, "gold.exr")}, ggx_mi)]
    if rgl and os.path.exists(rgl):
        rgl = os.path.abspath(rgl)  # the scene is written in a temporary folder and resolves paths from there
        name = os.path.splitext(os.path.basename(rgl))[0]
        subprocess.run([facetfit, "bake", rgl, "-o", lut_dir], check=True, capture_output=True)
        cases.append(("measured RGL (%s)" % name, {"type": "measured", "file": rgl, "proposal": os.path.join(lut_dir, name + ".exr")},
                      {"type": "measured", "file": rgl}))
    # Each case's facetfit runs alternate with Mitsuba llvm_ad_rgb's (side_by_side): on a shared machine the
    # load changes from minute to minute, and a ratio of runs minutes apart measured it. The scalar variant,
    # slower and only for reference, once per Mitsuba material.
    rows, scalar_cache = [], {}
    for spp in SPPS:
        for label, ff, mi_material in cases:
            key = (json.dumps(mi_material), spp)
            if key not in scalar_cache:
                scalar_cache[key] = mitsuba_run(mitsuba_python, "scalar_rgb", mi_material, spp, env)
            scalar = scalar_cache[key]
            if llvm:
                (f_render, f_process, f_memory), jit = side_by_side(facetfit, work, ff, mitsuba_python, mi_material, spp, env)
            else:
                (f_render, f_process, f_memory), jit = facetfit_run(facetfit, work, ff, spp), None
            rows.append((label, spp, f_render, f_process, f_memory, scalar, jit, mi_material["type"] == "ggx" and ff["type"] != "ggx"))
            print("%s %d spp: facetfit %.3f / %.3f s, scalar %.3f / %.3f s, llvm %s" % (
                label, spp, f_render, f_process, scalar[0], scalar[1], "%.3f / %.3f s" % jit[:2] if jit else "absent"), file=sys.stderr)

    cpus = os.cpu_count()
    one_cpu = ["taskset", "-c", "0"]
    scaling = [("facetfit", facetfit_run(facetfit, work, ggx_ff, 64, one_cpu)[0], rows[0][2]),
               ("Mitsuba scalar_rgb", mitsuba_run(mitsuba_python, "scalar_rgb", ggx_mi, 64, env, one_cpu)[0], rows[0][5][0])]
    if llvm:
        scaling.append(("Mitsuba llvm_ad_rgb", mitsuba_run(mitsuba_python, "llvm_ad_rgb", ggx_mi, 64, env, one_cpu)[0], rows[0][6][0]))
    # Mitsuba's GGX sphere with its kernels compiled for narrower vectors than the host's: how much of its
    # lead is vector width; and facetfit's GGX and LUT spheres with its AVX2 code where the host has AVX-512.
    widths, own_widths = [], []
    flags = open("/proc/cpuinfo").read() if os.path.exists("/proc/cpuinfo") else ""
    if llvm and " avx2" in flags:
        avx2 = "haswell:+avx2,+fma,+f16c,+bmi,+bmi2,+popcnt,+lzcnt,+sse4.2:"
        widths.append(("the host's (%s)" % ("AVX-512, 16 lanes" if " avx512f" in flags else "AVX2, 8 lanes"), rows[0][6][0]))
        for label, target in (("AVX2, 8 lanes", avx2 + "8"), ("AVX2, 4 lanes", avx2 + "4")):
            try:
                widths.append((label, mitsuba_run(mitsuba_python, "llvm_ad_rgb", ggx_mi, 64, dict(env, FACETFIT_LLVM_TARGET=target))[0]))
            except (subprocess.CalledProcessError, ValueError):
                widths.append((label, None))
    if " avx512f" in flags:
        no_avx3 = ["env", "FACETFIT_NO_AVX3=1"]
        own_widths = [("the host's (AVX-512, 8 doubles)", rows[0][2], rows[1][2]),
                      ("AVX2, 4 doubles", facetfit_run(facetfit, work, ggx_ff, 64, no_avx3)[0], facetfit_run(facetfit, work, cases[1][1], 64, no_avx3)[0])]
    # The GGX sphere's stages on one CPU: camera rays and hits alone, then each light alone, then both.
    stages = [(what, facetfit_run(facetfit, work, ggx_ff, 64, one_cpu, environment=e, light=l)[0]) for what, e, l in (
        ("camera rays and their hits alone (no light, no environment)", False, False),
        ("and the directional light (an evaluation and a shadow ray per hit)", False, True),
        ("and the environment instead (a BRDF sample, its evaluation and its shadow ray per hit; a constant environment has no light sample)", True, False))]
    # The whole scene with a Lambertian sphere: a BRDF whose sampling and evaluation cost next to nothing, so
    # its time is what the pipeline around any material's BRDF costs.
    floor = facetfit_run(facetfit, work, {"type": "lambert", "albedo": [0.8, 0.8, 0.8]}, 64, one_cpu)[0]
    stages.append(("both, with a Lambertian sphere instead (its sampling and evaluation next to free: what every material pays)", floor))
    lut_one_cpu = facetfit_run(facetfit, work, cases[1][1], 64, one_cpu)[0] if llvm else None  # against Mitsuba's LLVM time
    stages.append(("both (the scene above)", scaling[0][1]))
    # Noise at 64 spp, on the spheres both renderers render themselves (not the proxies).
    variant = "llvm_ad_rgb" if llvm else "scalar_rgb"
    at64 = [row for row in rows if row[1] == 64]
    noises = [(label, noise(facetfit, mitsuba_python, work, ff, mi_material, 64, env, variant), row)
              for (label, ff, mi_material), row in zip(cases, at64) if not row[7]]
    profiles = [(label, profile(facetfit, work, ff)) for label, ff, _ in cases[:2]]
    startup = start_up(facetfit)
    report = (0, 0.0, "")
    if rgl:
        db = os.path.dirname(rgl)
        start = time.perf_counter()
        subprocess.run([facetfit, "report", db, "-o", os.path.join(work, "report")], check=True, capture_output=True)
        elapsed = time.perf_counter() - start
        usage = subprocess.run([facetfit, "report", "--help"], check=True, capture_output=True, text=True).stdout
        size, spp = (re.search(r"--%s INT=(\d+)" % flag, usage).group(1) for flag in ("size", "spp"))
        report = (len([f for f in os.listdir(db) if f.endswith(".bsdf")]), elapsed, "%s x %s, %s spp" % (size, size, spp))
    with open(dst + ".tmp", "w") as out:
        out.write("# Reference renderer against Mitsuba 3\n\nGenerated by `make bench` (bench/render_compare.py); do not edit by hand.\n\n")
        out.write("The scene of `../shared/data/realref` at %d x %d (constant environment 0.3, one directional light, a unit\n"
                  "sphere; direct lighting), %d CPUs, every renderer on all of them, median of %d runs (one at 1024 spp; facetfit's in turn with Mitsuba LLVM's), Mitsuba 3 from PyPI.\n"
                  "*render*: one render (facetfit: the time it prints, including loading the material and building the\n"
                  "scene; Mitsuba: the second render in its process, scene loaded and kernels compiled). *process*: launch\n"
                  "to exit (llvm_ad_rgb with a warm kernel cache). Ratios are facetfit's time over Mitsuba's: below 1,\n"
                  "facetfit is faster. Rows marked * compare with Mitsuba's GGX sphere, which it renders instead.\n\n"
                  % (SIZE, SIZE, cpus, RUNS))
        out.write("| sphere | spp | facetfit render | process | Mitsuba llvm_ad_rgb render | process | scalar_rgb render | process | render / llvm | process / llvm | render / scalar |\n")
        out.write("|---|---|---|---|---|---|---|---|---|---|---|\n")
        for label, spp, fr, fp, fm, scalar, jit, proxy in rows:
            jr = "%.3f s" % jit[0] if jit else "n/a"
            jp = "%.3f s" % jit[1] if jit else "n/a"
            rr = "%.2f" % (fr / jit[0]) if jit else "n/a"
            rp = "%.2f" % (fp / jit[1]) if jit else "n/a"
            out.write("| %s%s | %d | %.3f s | %.3f s | %s | %s | %.3f s | %.3f s | %s | %s | %.2f |\n" % (
                label, " *" if proxy else "", spp, fr, fp, jr, jp, scalar[0], scalar[1], rr, rp, fr / scalar[0]))
        if not llvm:
            out.write("\nMitsuba's llvm_ad_rgb variant was not run: %s is absent (Debian package libllvm19).\n" % LLVM)
        out.write("\nPeak memory of one render process (resident set): facetfit %s; Mitsuba llvm_ad_rgb %s, scalar_rgb %s\n"
                  "(GGX sphere, 64 and 1024 spp).\n" % (
                      ", ".join("%.0f MiB" % r[4] for r in rows if r[0] == "GGX 0.3"),
                      ", ".join("%.0f MiB" % r[6][2] for r in rows if r[0] == "GGX 0.3" and r[6]) or "n/a",
                      ", ".join("%.0f MiB" % r[5][2] for r in rows if r[0] == "GGX 0.3")))
        out.write("\n## Scaling\n\nThe GGX sphere at 64 spp on one CPU (`taskset -c 0`) and on all %d; speed-up = one CPU's time over all.\n\n" % cpus)
        out.write("| renderer | render, 1 CPU | render, %d CPUs | speed-up |\n|---|---|---|---|\n" % cpus)
        for name, one, all_ in scaling:
            out.write("| %s | %.3f s | %.3f s | %.2f |\n" % (name, one, all_, one / all_))
        if widths:
            out.write("\n## Vector width\n\nMitsuba's llvm_ad_rgb variant compiles its kernels for the host's widest vectors: 16\n"
                      "single-precision lanes with AVX-512, 8 with AVX2. facetfit runs double precision, 8 lanes with AVX-512\n"
                      "and 4 with AVX2 (render/simd_targets.h), in its GGX and MERL kernels and in a tile's hits, light and\n"
                      "BRDF samples, shadow rays and their values (render/wavefront.h, render/sphere_batch.h); the tabulated\n"
                      "lobe's draws and evaluations run single precision, 16 and 8 lanes (render/tabulated_batch.h). The GGX sphere\n"
                      "at 64 spp with Mitsuba's kernels compiled for narrower vectors (Dr.Jit's `jit_llvm_set_target`), against\n"
                      "facetfit's render in the table at the top (%.3f s):\n\n| Mitsuba llvm_ad_rgb target | render | facetfit render / Mitsuba's |\n"
                      "|---|---|---|\n" % rows[0][2])
            for label, seconds in widths:
                out.write("| %s | %s | %s |\n" % (label, "%.3f s" % seconds if seconds else "n/a",
                                                   "%.2f" % (rows[0][2] / seconds) if seconds else "n/a"))
        if own_widths:
            out.write("\nfacetfit's spheres at 64 spp with its AVX2 code on the same host (`FACETFIT_NO_AVX3=1`):\n\n"
                      "| facetfit target | GGX sphere | tabulated LUT sphere |\n|---|---|---|\n")
            for label, ggx_seconds, lut_seconds in own_widths:
                out.write("| %s | %.3f s | %.3f s |\n" % (label, ggx_seconds, lut_seconds))
        out.write("\n## Noise at equal samples\n\nA render's time is half of its cost; the other half is its noise. Two renders of each\n"
                  "renderer at 64 spp with different seeds (Mitsuba: %s), over the pixels the sphere covers wholly\n"
                  "(%d): the variance of one render per pixel and channel, E[(a - b)^2] / 2, and the mean of both. Variance\n"
                  "falls as 1 / spp, so *time to equal noise* = (facetfit's render time x its variance) / (Mitsuba's x\n"
                  "its): the ratio of the times the two need for the same noise. Per sample facetfit lights a hit by every\n"
                  "light (the directional light's shadow ray each sample) and by one BRDF sample for the environment (a\n"
                  "map also gets a light sample, the two weighted by multiple importance sampling: render/integrator.cpp;\n"
                  "a constant environment's uniform light sample, so weighted, added noise: at 64 spp the variance of the\n"
                  "GGX sphere fell from 0.00023 to 0.000132 and of the LUT sphere from 0.000149 to 0.0000838 without it,\n"
                  "one-off measurement of 2026-12-05). Mitsuba's `direct` integrator draws one emitter sample, from one of\n"
                  "the scene's emitters picked at random, and one BSDF sample: two evaluations per sample, as facetfit here.\n"
                  "The table at the top compares equal samples, not equal noise, and stays the measure of the render's speed.\n\n"
                  % (variant, noises[0][1]["pixels"] if noises else 0))
        out.write("| sphere | facetfit variance | Mitsuba variance | variance ratio | facetfit mean | Mitsuba mean | render / Mitsuba (64 spp) | time to equal noise / Mitsuba |\n"
                  "|---|---|---|---|---|---|---|---|\n")
        for label, n, row in noises:
            mitsuba_time = row[6][0] if row[6] else row[5][0]
            ratio = n["facetfit"]["variance"] / n["mitsuba"]["variance"]
            out.write("| %s | %.3g | %.3g | %.3f | %.4f | %.4f | %.2f | %.3f |\n" % (
                label, n["facetfit"]["variance"], n["mitsuba"]["variance"], ratio, n["facetfit"]["mean"], n["mitsuba"]["mean"],
                row[2] / mitsuba_time, row[2] / mitsuba_time * ratio))
        out.write("\n## Start-up\n\nA process that loads the render command and exits at once (`facetfit render --help`), median of %d: "
                  "%.3f s; the command plugin and the shared libraries it needs: %d (OpenImageIO, ~260 more, is a module of its own, "
                  "loaded only for images other than OpenEXR: io/image_file.h), "
                  "whose symbol lookups by the dynamic loader take %s of that time (`perf record`). A render's process time "
                  "is its render time plus this.\n" % (RUNS, startup[0], startup[1], startup[2]))
        out.write("\n## Where the time goes\n\n`perf record` of one facetfit render (64 spp, whole process), self time by\n"
                  "library and symbol (the sphere is intersected in closed form, render/tracer.h; Embree traces triangles only).\n"
                  "A tile's samples are shaded in steps (render/integrator_streams.cpp), each in SIMD lanes over the tile (`N_AVX3::` on\n"
                  "an AVX-512 host, `N_AVX2::` with AVX2): their numbers and camera rays (`DrawCameraSamples`,\n"
                  "render/camera_batch.h), the spheres' hits (`NearestSpheresFromPoint` for camera rays, render/sphere_batch.h),\n"
                  "the tile's hit columns (`TakeHits`, render/wavefront.h), the hits placed per\n"
                  "material (`PlaceHits`, render/wavefront.h), the slots of an environment map's light sample and of the lights\n"
                  "(`LightSlots`), BRDF sampling (`SampleGgxBatch`, `SampleTabulatedBatch`) and its slots (`BrdfSlots`),\n"
                  "evaluation (`EvalGgxBatch`, render/ggx_batch.h; `EvalTabulatedBatch`, render/tabulated_batch.h; a\n"
                  "MERL-layout table's f, `EvalMerlBatch`, render/merl_batch.h), the shadow rays' values (`ShadowValues`)\n"
                  "and blocking (`BlockedBySpheres`); the tile loop (`render::{lambda}`) adds the unblocked values to\n"
                  "their pixels and the sample to the pixels' sums (`AddSamples`). A hit whose model has no lanes (an RGL or UTIA file's own evaluation, a lobe\n"
                  "textured per hit) is shaded one pair at a time inside the tile loop. On AVX-512 the kernels divide by\n"
                  "AVX-512's 14-bit reciprocal estimate refined by two Newton steps (render/lanes-inl.h: `reciprocal`,\n"
                  "`divide`, `inverse_sqrt`; vdivpd on eight doubles issues once per 16 cycles): 12% of the GGX sphere's\n"
                  "render (perf stat, one CPU, 346 -> 311 ms); square roots as x times the refined inverse square root were\n"
                  "slower than vsqrtpd in the GGX kernels (325 ms) and stay hardware there, but not in the tabulated\n"
                  "lobe's grid lookups, two square roots each (below). Sines and cosines are a series of their own\n"
                  "(`cos_sin`, no argument reduction: 311 -> 299 ms). The tabulated lobe's sampler inverted its\n"
                  "azimuth's CDF by Newton steps from a table's guess (model/visible_azimuth.h: 2.3 steps for the\n"
                  "slowest of 8 lanes where the start u phi_max took 5.4; the LUT sphere 560 -> 528 ms); the renderer\n"
                  "now draws a tabulated lobe's visible normals in slope space from tables, with no root to find\n"
                  "(model/visible_slopes.h, docs/sampling.md). The\n"
                  "Lambertian sphere (below), one CPU: the tile loop adds the lanes' values and sums the samples in\n"
                  "per-tile columns, no branch per shadow ray (259 -> 251 ms); SplitMix64's 64-bit products by\n"
                  "AVX-512's vpmullq (261 -> 251 ms); a hit carries only the columns the scene reads, no position\n"
                  "without a point light, a constant environment's radiance once (243 -> 234 ms, the mean of five\n"
                  "alternated runs, within this machine's noise that day). On 2026-12-05 (one CPU, medians of five\n"
                  "alternated runs): the tabulated kernels' arc cosine and square roots by the refined inverse square\n"
                  "root, the visible normals' density per cos(theta_h) tabulated once (two gathers where six were), the\n"
                  "running sums searched from a guide of 64 entries per view slice, no density for a light's slots (LUT\n"
                  "sphere 455 -> 424 ms); a constant environment lit by the BRDF sample alone (LUT 420 -> 366 ms, GGX\n"
                  "253 -> 197 ms, Lambertian 219 -> 175 ms, and less noise: \"Noise at equal samples\"); misses shaded in the tile loop and\n"
                  "the sums added in a vectorized loop (Lambertian 184 -> 165 ms); one division per shadow value. Later\n"
                  "that day: the tabulated proposals' visible slopes (LUT sphere 364 -> 320 ms, MERL 682 -> 594 ms, the\n"
                  "same variance). Later, on an AVX2 host (AMD EPYC of family 23, Zen; CPU time of one CPU, medians of\n"
                  "alternated runs while other jobs ran): the tabulated lobe's kernels in single precision (LUT 1313 ->\n"
                  "884 ms, MERL 2712 -> 2281 ms; the images differ by a mean Delta E of 0.00008); AVX2's eight-lane\n"
                  "gathers as eight loads, Zen's vgatherdps being microcoded (LUT 1052 -> 954 ms); four neighbouring\n"
                  "table entries per lane loaded together and transposed (the spline's nodes, G1's, the Fresnel curve's,\n"
                  "a draw's next sums: LUT 931 -> 834 ms, the same image); the camera stage draws only the numbers the\n"
                  "scene reads, made by an or (AVX2 has no 64-bit integer conversion). The next session, same host:\n"
                  "two 32-bit numbers from each SplitMix64 mix (three mixes a sample where there were five, each two\n"
                  "emulated 64-bit products on AVX2), a sphere's normal as (p - centre) / radius (no square root or\n"
                  "division per hit) and no permutation where a compaction keeps every lane (LUT 737 -> 675 ms; the\n"
                  "noise the same: against a 1024-spp render, mean Delta E 0.627 where the old numbers with another\n"
                  "seed gave 0.630); the tracer's hits in columns, taken into the tile's columns in lanes (689 -> 644\n"
                  "ms); the sums added in lanes and the slots' values without a branch; camera rays traced from one\n"
                  "point and read in place, no copies (1.9% of the render in memmove).\n"
                  "Tried and left: a product by 2 / pi for the grid's quotient by pi / 2 (1%); the view's grid position\n"
                  "shared by a hit's four lookups (at most 4-6% of the LUT sphere, measured by leaving three out); a\n"
                  "guide of 256 entries, an azimuth guess of 64 x 64 nodes and tiles of 8 x 8 pixels (within noise); on\n"
                  "Zen, single-precision divisions and square roots from AVX2's estimates and a Newton step (LUT 724 ->\n"
                  "778 ms: these kernels wait on their many operations, not on the divider) and the camera rays'\n"
                  "lengths from the estimate and three Newton steps (within noise).\n")
        out.write("\nBy stage: the GGX sphere at 64 spp on one CPU with parts of the scene left out (one render each, the\n"
                  "median of %d); the camera stage (the numbers and camera rays in SIMD lanes, render/camera_batch.h, the\n"
                  "sphere's hits, each hit's frame, the accumulation) is what every sample pays.\n\n"
                  "| the samples' work | facetfit render, 1 CPU | share of the whole |\n|---|---|---|\n" % RUNS)
        for what, seconds in stages:
            out.write("| %s | %.3f s | %.0f%% |\n" % (what, seconds, 100.0 * seconds / stages[-1][1]))
        if llvm:
            out.write("\nMitsuba 3 llvm_ad_rgb renders the whole scene on one CPU in %.3f s (Scaling above)" % scaling[-1][1])
            ratio = stages[-2][1] / scaling[-1][1]
            if ratio >= 1.0:
                out.write(": the Lambertian sphere's %.3f s, %.2f of that, is already more, so no tabulated BRDF, however\n"
                          "cheap, renders the LUT sphere in less than Mitsuba's GGX time without a faster pipeline around it.\n"
                          % (stages[-2][1], ratio))
            else:
                out.write(", %.2f of the Lambertian sphere's %.3f s.\n" % (1.0 / ratio, stages[-2][1]))
            out.write("The tabulated LUT sphere takes %.3f s on one CPU, %.2f of Mitsuba's GGX time: its sampling and evaluation\n"
                      "add %.3f s to the Lambertian floor, where %.3f s would leave it under Mitsuba's.\n"
                      % (lut_one_cpu, lut_one_cpu / scaling[-1][1], lut_one_cpu - stages[-2][1], max(0.0, scaling[-1][1] - stages[-2][1])))
        for label, (rows_, libraries) in profiles:
            out.write("\n%s, by library: %s.\n\n| self | library | symbol |\n|---|---|---|\n" % (
                label, ", ".join("%s %.0f%%" % (dso, pct) for dso, pct in libraries) or "n/a"))
            if not rows_:
                out.write("| n/a | linux-perf is not installed or not permitted | |\n")
            for pct, dso, sym in rows_:
                out.write("| %.1f%% | %s | `%s` |\n" % (pct, dso, sym.replace("|", "\\|")))
        if report[0]:
            out.write("\n## Report throughput\n\n`facetfit report` at its default quality (%s) on the %d RGL materials\n"
                      "beside the RGL file above, cold bake cache: %.1f s, %.1f materials per minute (bake, four renders and\n"
                      "their Delta E per material).\n" % (report[2], report[0], report[1], 60.0 * report[0] / report[1]))
    os.replace(dst + ".tmp", dst)


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(*sys.argv[1:5])
