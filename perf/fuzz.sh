#!/usr/bin/env bash
# Fuzzes the parsers (tests/fuzz/): each target for RUNS executions with libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer, starting from its seed corpus; prints executions, seconds and the outcome per target.
#   perf/fuzz.sh [RUNS] [TARGET...]        RUNS: default 1000000; TARGETs: default all
# Env: FUZZ_SECONDS stops a target after that long (its count then tells how far it got), FUZZ_BUILD (default build-fuzz; built with clang++-14 when it holds no kushner_fuzz), FUZZ_PARALLEL=1 runs
# the targets side by side, FUZZ_OUT (default $FUZZ_BUILD/fuzz-out) receives the logs, the grown corpora (the
# committed seeds stay as they are) and any crashing input, which belongs in tests/fuzz/regressions/<target>/.
# Exit 1 when any target crashed, hung, leaked or broke a sanitizer rule.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-1000000}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(config_file model_file set_value name_lists paper_values)
build=${FUZZ_BUILD:-$root/build-fuzz}
out=${FUZZ_OUT:-$build/fuzz-out}
if [ ! -x "$build/kushner_fuzz" ]; then
  cmake -S "$root/tests/fuzz" -B "$build" -DCMAKE_CXX_COMPILER=clang++-14 >/dev/null
  cmake --build "$build" -j "$(nproc)"
fi
mkdir -p "$out"

fuzz_one() {
  local target=$1
  rm -rf "${out:?}/$target" "$out/$target-"*
  mkdir -p "$out/$target"
  local start=$SECONDS rc=0
  # -timeout: an input slower than 10 s is a hang; -rss_limit_mb: more than 2 GB is a memory blow-up.
  KUSHNER_FUZZ_TARGET=$target "$build/kushner_fuzz" -runs="$runs" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
    -max_total_time="${FUZZ_SECONDS:-0}" -print_final_stats=1 -artifact_prefix="$out/$target-" "$out/$target" "$root/tests/fuzz/corpus/$target" \
    >"$out/$target.log" 2>&1 || rc=$?
  local executed
  executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$target.log" | tail -1)
  local outcome="ok"
  [ "$rc" -eq 0 ] || outcome="FAILED (exit $rc; $(grep -m1 -E 'ERROR|fuzz check failed' "$out/$target.log" || true))"
  printf '%-13s %10s executions %6s s  %s\n' "$target" "${executed:-?}" $((SECONDS - start)) "$outcome" \
    >"$out/$target.result"
  [ "$rc" -eq 0 ]
}

failed=0
if [ "${FUZZ_PARALLEL:-0}" = 1 ]; then
  pids=()
  for t in "${targets[@]}"; do fuzz_one "$t" & pids+=($!); done
  for p in "${pids[@]}"; do wait "$p" || failed=1; done
else
  for t in "${targets[@]}"; do fuzz_one "$t" || failed=1; done
fi
for t in "${targets[@]}"; do cat "$out/$t.result"; done
ls "$out" | grep -E -- '-(crash|timeout|leak|oom|slow-unit)-' || echo "no crash, hang, leak or sanitizer report"
exit $failed
