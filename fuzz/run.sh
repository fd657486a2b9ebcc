#!/usr/bin/env bash
# run.sh BUILD_DIR SECONDS [TARGET...]: runs each fuzz target for SECONDS under ASan + UBSan, from its
# seeds (fuzz/seeds/TARGET, plus generated binary seeds), with a private corpus in BUILD_DIR/corpus;
# exits nonzero if any target finds something (the crashing input is kept in BUILD_DIR/findings). Prints
# the executions per second and coverage each reached.
set -euo pipefail
build=$1; seconds=$2; shift 2
here="$(cd "$(dirname "$0")" && pwd)"
# Default: every harness of fuzz/ (fuzz_NAME.cpp).
if [[ $# -gt 0 ]]; then targets=("$@"); else targets=(); for f in "$here"/fuzz_*.cpp; do n=$(basename "$f" .cpp); targets+=("${n#fuzz_}"); done; fi
mkdir -p "$build/findings"
python3 "$here/make_seeds.py" "$build/seeds"
"$build/fuzz/write_seeds" "$build/seeds"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# One target: runs it, writes its line of the summary to fuzz_TARGET.result and exits nonzero on a finding.
fuzz_one() {
  local t=$1 corpus="$build/corpus/$1" log="$build/fuzz_$1.log" seeds=() d max_len runs cov ok=0
  rm -f "$build/fuzz_$t.result"
  mkdir -p "$corpus"
  for d in "$build/seeds/$t" "$here/seeds/$t"; do [[ -d "$d" ]] && seeds+=("$d"); done
  # 64 KiB, or the harness's own `// max_len: N` line.
  max_len=$(sed -n 's|^// max_len: \([0-9]*\).*|\1|p' "$here/fuzz_$t.cpp"); max_len=${max_len:-65536}
  run_target() {
    "$build/fuzz/fuzz_$t" "$corpus" "${seeds[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -max_len="$max_len" -artifact_prefix="$build/findings/$t-" -print_final_stats=1 >"$log" 2>&1
  }
  {
    if run_target; then
      ok=1
    elif grep -qE "LeakSanitizer has encountered a fatal error|Tracer caught signal" "$log"; then
      # LeakSanitizer's own tracer (it stops the process under ptrace to scan it) can fail on a shared
      # machine, and libFuzzer reports that as a crash of whatever input ran last (it was once the empty
      # input). Not the target's fault: the target runs again, and a second failure is a finding.
      echo "fuzz_$t: LeakSanitizer's tracer failed (not a finding of the target); running it again"
      mv "$log" "$log.tracer"
      if run_target; then ok=1; fi
    fi
    if [[ $ok == 1 ]]; then
      runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
      cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
      echo "fuzz_$t: ${seconds} s, $runs executions ($((${runs:-0} / seconds))/s), coverage $cov edges, no finding"
    else
      echo "fuzz_$t: FINDING (log $log, input in $build/findings/):"; grep -m5 -E "ERROR|SUMMARY|runtime error|deadly signal|timeout" "$log" || tail -20 "$log"
    fi
  } >"$build/fuzz_$t.result"
  [[ $ok == 1 ]]
}

# FUZZ_JOBS targets at a time (default: one per core), each for the whole of SECONDS on its own core.
parallel=${FUZZ_JOBS:-$(nproc)}
declare -A pid_of
for t in "${targets[@]}"; do
  while (( $(jobs -rp | wc -l) >= parallel )); do wait -n || true; done
  fuzz_one "$t" & pid_of[$t]=$!
done
status=0
for t in "${targets[@]}"; do
  wait "${pid_of[$t]}" || status=1
  cat "$build/fuzz_$t.result" 2>/dev/null || echo "fuzz_$t: FINDING or failure before it ran (log $build/fuzz_$t.log)"
done
exit $status
