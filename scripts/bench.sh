#!/usr/bin/env bash
# Runs the Google Benchmark suite and writes docs/benchmarks.md from its JSON (make bench).
set -euo pipefail
build="${1:-build/release}"
root="$(cd "$(dirname "$0")/.." && pwd)"
json="$(mktemp --suffix=.json)"
trap 'rm -f "$json"' EXIT
"$build/bench/facetfit_bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_min_time=0.3 --benchmark_out="$json" --benchmark_out_format=json
startup_ms=$(python3 - "$build/bin/facetfit" <<'PY'
import statistics, subprocess, sys, time
times = []
for _ in range(10):
    t = time.perf_counter()
    subprocess.run([sys.argv[1], "--version"], check=True, stdout=subprocess.DEVNULL)
    times.append((time.perf_counter() - t) * 1e3)
print(statistics.median(times))
PY
)
python3 "$root/scripts/bench_to_md.py" "$json" "$root/docs/benchmarks.md" "$startup_ms"
"$build/bench/facetfit_pareto" "$root/docs"
# Cycles through Blender's bpy wheel, in a venv of the build.
py=$("$root/scripts/setup-bpy.sh" "$build/../bpy-venv" | tail -n 1)
"$py" "$root/scripts/cycles_compare.py" "$build/bin/facetfit" "$root/docs/cycles.md"
echo "wrote docs/benchmarks.md"
