#!/usr/bin/env bash
# The MaterialX route into Cycles, measured (docs/osl.md, "In production"): each RGL material of SHARED_DATA
# baked, exported as MaterialX (facetfit export), turned into OSL by MaterialX's own generator
# (tests/materialx/genosl.py, with PY_PYTHON: build/py-venv, make python), and rendered by Cycles in the
# scene of realref (BPY_PYTHON: build/bpy-venv, make osl-host) beside osl/facetfit_material.osl of the same
# LUT. Prints a Markdown table: mean Delta E 2000 of the generated shader's render against the material
# shader's, and of each against Mitsuba's render of the measurement.
# Usage: scripts/materialx_cycles.sh FACETFIT [SHARED_DATA] [SPP] [BAKE FLAGS...]
#   e.g. scripts/materialx_cycles.sh build/release/bin/facetfit ../shared/data 64 --closure-fresnel schlick
set -euo pipefail
facetfit=$1 data=${2:-../shared/data} spp=${3:-64}
bake_flags=("${@:4}")
bpy_python=${BPY_PYTHON:-build/bpy-venv/bin/python}
py_python=${PY_PYTHON:-build/py-venv/bin/python}
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$facetfit" bake "$data/rgl" -o "$work/luts" "${bake_flags[@]}" >/dev/null 2>&1
diff_mean() {
  "$facetfit" diff "$1" "$2" --mask "$data/realref/mask.exr" --json | python3 -c 'import json, sys; print("%.2f" % json.load(sys.stdin)["mean"])'
}
render() {  # SHADER OUT [NAME=VALUE]
  "$bpy_python" "$data/realref/cycles_scene.py" "$1" "$2" "$spp" "${@:3}" >"$work/cycles.log" 2>&1 ||
    { echo "materialx_cycles: Cycles failed on $1:" >&2; tail -5 "$work/cycles.log" >&2; exit 1; }
}
echo "| material | MaterialX's OSL against facetfit_material.osl | MaterialX's OSL against Mitsuba | facetfit_material.osl against Mitsuba |"
echo "|---|---|---|---|"
for lut in "$work"/luts/*.exr; do
  name=$(basename "$lut" .exr)
  "$facetfit" export "$lut" -o "$work/mtlx" >/dev/null
  osl=$("$py_python" "$here/tests/materialx/genosl.py" "$work/mtlx/$name.mtlx" "$work/osl")
  render "$osl" "$work/mx.exr"
  render "$here/osl/facetfit_material.osl" "$work/material.exr" "lut=$lut"
  echo "| $name | $(diff_mean "$work/mx.exr" "$work/material.exr") | $(diff_mean "$work/mx.exr" "$data/realref/$name.exr") | $(diff_mean "$work/material.exr" "$data/realref/$name.exr") |"
done
echo
echo "Cycles at $spp samples per pixel, 128 x 128, over realref/mask.exr (scripts/materialx_cycles.sh${bake_flags[*]:+, bake ${bake_flags[*]}})."
