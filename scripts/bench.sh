#!/usr/bin/env bash
# Runs the Google Benchmark suite and writes docs/benchmarks.md from its JSON (make bench).
set -euo pipefail
build="${1:-build/release}"
root="$(cd "$(dirname "$0")/.." && pwd)"
json="$(mktemp --suffix=.json)"
trap 'rm -f "$json"' EXIT
"$build/bench/facetfit_bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_min_time=0.3 --benchmark_out="$json" --benchmark_out_format=json
startup="$(mktemp --suffix=.md)"
trap 'rm -f "$json" "$startup"' EXIT
python3 "$root/bench/startup.py" "$build/bin/facetfit" "$startup" 10 "$root/../shared/data/rgl/ilm_l3_37_metallic_rgb.bsdf"
python3 "$root/scripts/bench_to_md.py" "$json" "$root/docs/benchmarks.md" "$startup"
"$build/bench/facetfit_pareto" "$root/docs"
# The report's noise at its default spp and at 32, against 1024 (the floor report.h states).
python3 "$root/bench/report_noise.py" "$build/bin/facetfit" "$root/docs/report-noise.md"
# Cycles through Blender's bpy wheel, in a venv of the build.
py=$("$root/scripts/setup-bpy.sh" "$build/../bpy-venv" | tail -n 1)
"$py" "$root/scripts/cycles_compare.py" "$build/bin/facetfit" "$root/docs/cycles.md"
# The production material beside a Principled BSDF and MaterialX's OSL of its closures, in Cycles.
"$root/scripts/setup-python.sh" "$build/../py-venv" >/dev/null
BPY_PYTHON="$py" "$root/bench/osl_speed.sh" "$build/bin/facetfit" "$root/docs/osl-speed.md" "$root/../shared/data/rgl/cc_ibiza_sunset_rgb.bsdf"
# Mitsuba 3 (PyPI; llvm_ad_rgb through Debian's libllvm19) on the realref scene, with an RGL sphere where
# the shared data is present.
mpy=$("$root/scripts/setup-mitsuba.sh" "$build/../mitsuba-venv" | tail -n 1)
python3 "$root/bench/render_compare.py" "$build/bin/facetfit" "$mpy" "$root/docs/render-speed.md" \
  "$root/../shared/data/rgl/cc_ibiza_sunset_rgb.bsdf"
echo "wrote docs/benchmarks.md"
