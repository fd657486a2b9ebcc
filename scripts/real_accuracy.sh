#!/usr/bin/env bash
# Real-material accuracy: every RGL material of ../shared/data/rgl baked by facetfit, rendered by
# facetfit's renderer in the common scene of ../shared/data/realref, and compared with Mitsuba 3's
# renders there (mean CIE Delta E 2000 over realref/mask.exr). Adds (or replaces) the section with the table, and
# the mean and worst of each column, to OUT (docs/accuracy.md, which bench/accuracy_table.cpp has just written).
# The Cycles column renders the production material (osl/facetfit_material.osl) of the same LUT in Blender's
# Cycles through realref/cycles_scene.py, with BPY_PYTHON (default build/bpy-venv/bin/python: make osl-host).
# The neural column is the accuracy anchor: the material's neural BRDF (../shared/data/nbrdf, where present)
# tabulated by scripts/nbrdf_table.py with PY_PYTHON (numpy and h5py; default build/py-venv/bin/python: make
# python) and rendered as a measurement, in the same scene at the same samples.
# Usage: scripts/real_accuracy.sh FACETFIT OUT.md [SHARED_DATA] [SPP]
set -euo pipefail
facetfit=$1 out=$2 data=${3:-../shared/data} spp=${4:-256}
bpy_python=${BPY_PYTHON:-build/bpy-venv/bin/python}
py_python=${PY_PYTHON:-build/py-venv/bin/python}
here=$(cd "$(dirname "$0")" && pwd)
material_osl=$(cd "$here/../osl" && pwd)/facetfit_material.osl
section="## Rendered against Mitsuba 3: the RGL materials"
[[ -f "$out" ]] || { echo "real_accuracy: $out does not exist (bench/facetfit_accuracy writes it first)" >&2; exit 1; }
# The document without this script's section (under any of its titles), so that a second run replaces it
# rather than adding another.
kept=$(mktemp)
awk '/^## Rendered against Mitsuba 3/ { exit } { print }' "$out" | sed -e :a -e '/^\n*$/{$d;N;ba' -e '}' > "$kept"
if [[ ! -d "$data/rgl" || ! -d "$data/realref" ]]; then
  echo "real_accuracy: $data/rgl or $data/realref is absent: skipping the real-material table" >&2
  { cat "$kept"; printf '\n%s\n\nNot measured: %s/rgl or %s/realref was absent.\n' "$section" "$data" "$data"; } > "$out.tmp"
  mv "$out.tmp" "$out"
  rm -f "$kept"
  exit 0
fi
data=$(cd "$data" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work" "$kept"' EXIT
"$facetfit" bake "$data/rgl" -o "$work/paper" --refine none >/dev/null
start=$(date +%s)
"$facetfit" bake "$data/rgl" -o "$work/full" --refine full >/dev/null
seconds=$(($(date +%s) - start))

# mean_delta_e IMAGE NAME: mean Delta E 2000 of IMAGE against the reference render of NAME, over the mask.
mean_delta_e() {
  "$facetfit" diff "$1" "$data/realref/$2.exr" --mask "$data/realref/mask.exr" --json |
    python3 -c 'import json, sys; print("%.2f" % json.load(sys.stdin)["mean"])'
}

# delta_e TYPE LUT NAME: mean Delta E 2000 of the render of material TYPE from LUT against the reference.
delta_e() {
  python3 "$data/realref/scene.py" "$work/scene.json" "{\"type\": \"$1\", \"file\": \"$2\"}" "$spp"
  "$facetfit" render "$work/scene.json" -o "$work/render.exr" >/dev/null
  mean_delta_e "$work/render.exr" "$3"
}

# cycles_delta_e LUT NAME: the same for Cycles' render of the production material of LUT.
cycles_delta_e() {
  "$bpy_python" "$data/realref/cycles_scene.py" "$material_osl" "$work/cycles.exr" "$spp" "lut=$1" >"$work/cycles.log" 2>&1 ||
    { echo "real_accuracy: Cycles failed on $1:" >&2; tail -5 "$work/cycles.log" >&2; return 1; }
  mean_delta_e "$work/cycles.exr" "$2"
}

# neural_delta_e NAME: the same for the material's neural BRDF, tabulated as a MERL table; "-" without one.
neural_delta_e() {
  [[ -f "$data/nbrdf/$1.h5" ]] || { echo "-"; return; }
  "$py_python" "$here/nbrdf_table.py" "$data/nbrdf/$1.h5" "$work/neural.binary"
  delta_e measured "$work/neural.binary" "$1"
}

{
  echo "| material | paper (tabulated, --refine none) | tabulated | ggx | beckmann | lsq (Lambert + GGX + Schlick) | closures | Cycles (facetfit_material.osl) | neural | measured | recommended | Cycles at most neural |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
  for bsdf in "$data"/rgl/*.bsdf; do
    name=$(basename "$bsdf" .bsdf)
    row="| $name | $(delta_e lut "$work/paper/$name.exr" "$name")"
    declare -A rendered=()
    for type in lut ggx beckmann lsq closures; do
      rendered[$type]=$(delta_e "$type" "$work/full/$name.exr" "$name")
      row="$row | ${rendered[$type]}"
    done
    cycles=$(cycles_delta_e "$work/full/$name.exr" "$name")
    neural=$(neural_delta_e "$name")
    beats=$(awk -v c="$cycles" -v n="$neural" 'BEGIN { print n == "-" ? "-" : (c <= n ? "yes" : "no") }')
    # The bake's recommended representation, and whether it renders within 0.2 of the nearest of the five.
    recommended=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["representation"])' "$work/full/$name.json")
    column=$([[ $recommended == tabulated ]] && echo lut || echo "$recommended")
    near=$(printf '%s\n' "${rendered[@]}" | sort -g | head -1)
    within=$(awk -v r="${rendered[$column]}" -v n="$near" 'BEGIN { print r <= n + 0.2 ? "within 0.2" : "beyond 0.2" }')
    echo "$row | $cycles | $neural | $(delta_e measured "$bsdf" "$name") | $recommended ${rendered[$column]}, $within | $beats |"
    unset rendered
  done > "$work/rows.md"
  # Every cell a number (the neural one may be "-" where no network is given): a render or a diff that failed
  # must not enter the means as 0.
  if ! awk -F'|' '{ for (c = 3; c < NF - 2; ++c) if ($c !~ /^ *[0-9]+\.[0-9]+ *$/ && !(c == NF - 4 && $c ~ /^ *- *$/)) exit 1 }' "$work/rows.md"; then
    echo "real_accuracy: a cell is not a number:" >&2; cat "$work/rows.md" >&2; exit 1
  fi
  cat "$work/rows.md"
  # The mean and the worst of each column (a column's "-" cells left out of both).
  awk -F'|' '{ for (c = 3; c < NF - 2; ++c) if ($c !~ /^ *- *$/) { sum[c] += $c; count[c]++; if ($c > worst[c]) worst[c] = $c }
               if ($(NF - 2) ~ /within/) within++; if ($(NF - 1) ~ /yes/) beats++; if ($(NF - 1) ~ /yes|no/) compared++; n = NF; rows++ }
       END { printf "| mean"; for (c = 3; c < n - 2; ++c) printf " | %.2f", count[c] ? sum[c] / count[c] : 0
             printf " | %d of %d within 0.2 | %d of %d |\n", within, rows, beats, compared
             printf "| worst"; for (c = 3; c < n - 2; ++c) printf " | %.2f", worst[c]; print " | | |" }' "$work/rows.md"
  echo
  echo "facetfit and Cycles render at $spp samples per pixel; \`measured\` renders the file itself through its own evaluation (view slices, negative entries kept: what Mitsuba renders), the floor of what any fit can reach; \`neural\` the material's neural BRDF (../shared/data/nbrdf: Sztrajman et al. 2021) evaluated into a MERL table at the bins' lower edges, phi_d averaged with phi_d + pi (scripts/nbrdf_table.py), rendered as a measurement. Baking the $(ls "$data"/rgl/*.bsdf | wc -l) materials with \`--refine full\` took ${seconds} s on this machine (2 cores)."
} > "$work/table.md"
{
  cat "$kept"
  echo
  echo "$section"
  echo
  echo "Generated by \`make accuracy\` (scripts/real_accuracy.sh). Mean CIE Delta E 2000 against Mitsuba 3's renders of"
  echo "the RGL materials (../shared/data/realref), each material baked by facetfit and rendered by facetfit's"
  echo "renderer in the same scene. Columns: the paper's method alone (\`--refine none\`), then the representations of"
  echo "\`--refine full\` (tabulated = body + tabulated lobe + coat; ggx, beckmann = body + parametric lobe + optional coat,"
  echo "F82-tint Fresnel; lsq = the classical Lambert + GGX + Schlick least-squares fit; closures = the closure representation,"
  echo "body + one to three GGX lobes + coat, lib/model/closures.h), then the production material osl/facetfit_material.osl of the"
  echo "same LUT (what it recommends: a one-lobe fit or the closures) rendered by Blender's Cycles (bpy 5.0.1, OSL on the CPU; realref/cycles_scene.py), then the neural anchor."
  echo "Bars (issue 58): Cycles' mean at most the neural mean, none above 2.5; the tabulated mean at most the neural mean,"
  echo "none above 3.0, each material at most its lsq. \`recommended\`: the bake's recommended representation (fit/recommend.h),"
  echo "its render, and whether that is within 0.2 of the nearest of the five facetfit renders (issue 59's bar). The last column"
  echo "says, per material, whether the production material (Cycles) renders at least as near Mitsuba's as the neural BRDF does."
  echo
  cat "$work/table.md"
} > "$work/doc.md"
cp "$work/doc.md" "$out.tmp" && mv "$out.tmp" "$out"
echo "real_accuracy: added the real-material table to $out"
