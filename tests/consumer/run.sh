#!/usr/bin/env bash
# run.sh BUILD_DIR SOURCE_DIR: installs BUILD_DIR into a temporary prefix, checks that only the public
# headers are installed, builds tests/consumer against it with find_package(facetfit), runs it on a
# built-in material (fit, LUT, render), and runs the installed command (whose
# plugin must be found in the installed tree).
set -euo pipefail
build=$1; src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
test -f "$tmp/prefix/include/facetfit/fit/fit.h"
test -f "$tmp/prefix/lib/cmake/facetfit/facetfitConfig.cmake"
test -f "$tmp/prefix/share/facetfit/osl/facetfit.h"
# The public headers alone: nothing of the renderer's kernels, Highway or Embree (lib/CMakeLists.txt).
if ls "$tmp/prefix/include/facetfit/render" | grep -qvE '^(renderer|scene)\.h$' || grep -rqE 'hwy/|embree|HWY_' "$tmp/prefix/include/facetfit"; then
  echo "installed headers beyond the public API:" >&2; ls -R "$tmp/prefix/include/facetfit" >&2; exit 1
fi
cmake -S "$src/tests/consumer" -B "$tmp/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/build" >/dev/null
out=$("$tmp/build/consumer" builtin:gold-ggx-0.15 "$tmp/gold.exr")
echo "$out"
case "$out" in "alpha_ggx 0.15"*"read back 0.15"*"rendered 32x32"*) ;; *) echo "unexpected: $out" >&2; exit 1 ;; esac
"$tmp/prefix/bin/facetfit" fit builtin:gold-ggx-0.15 --refine none >/dev/null
"$tmp/prefix/bin/facetfit" bake builtin:gold-ggx-0.15 -o "$tmp/luts" --refine none >/dev/null
test -f "$tmp/luts/gold-ggx-0.15.exr"
echo "installed library and command work"
