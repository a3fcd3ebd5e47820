#!/usr/bin/env bash
# Where CI's compile time goes: builds the tree in a fresh directory with a launcher that times every
# compiler call, then prints the translation units by CPU seconds (user + sys), slowest first, with each call's peak
# memory, and the total.
# CI is bound by total CPU seconds on 2 cores, so that total (not the wall time on a big machine) is the
# figure to cut.
#   perf/compile_profile.sh BUILD_DIR [cmake configure args...]   (JOBS=<n>, default nproc; TARGET=<one target>)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:?usage: perf/compile_profile.sh BUILD_DIR [cmake args...]}
shift
mkdir -p "$build"
build=$(cd "$build" && pwd)
log=$build/compile_times.tsv
launcher=$build/time_compile.sh
cat >"$launcher" <<'SH'
#!/usr/bin/env bash
# Runs one compiler call under /usr/bin/time (else timed by the clock); appends "cpu_seconds<TAB>output<TAB>peak_MB"
# to $KUSHNER_COMPILE_LOG (peak resident memory of the largest process the call ran; 0 where unknown).
out=unknown
prev=
for a in "$@"; do [ "$prev" = "-o" ] && out=$a; prev=$a; done
if [ -x /usr/bin/time ]; then
  t=$(mktemp)
  /usr/bin/time -f "%U %S %M" -o "$t" "$@"
  rc=$?
  awk -v o="$out" '{printf "%.1f\t%s\t%.0f\n", $1 + $2, o, $3 / 1024}' "$t" >>"$KUSHNER_COMPILE_LOG"
  rm -f "$t"
else  # wall seconds: CPU seconds too while the build has a core per job
  s=$(date +%s.%N)
  "$@"
  rc=$?
  awk -v a="$s" -v b="$(date +%s.%N)" -v o="$out" 'BEGIN {printf "%.1f\t%s\t0\n", b - a, o}' >>"$KUSHNER_COMPILE_LOG"
fi
exit $rc
SH
chmod +x "$launcher"
: >"$log"
export KUSHNER_COMPILE_LOG=$log
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER="$launcher" "$@" >/dev/null
start=$(date +%s)
cmake --build "$build" -j "${JOBS:-$(nproc)}" ${TARGET:+--target $TARGET} >"$build/build.log" 2>&1 || { tail -30 "$build/build.log"; exit 1; }
echo "wall: $(( $(date +%s) - start )) s with ${JOBS:-$(nproc)} jobs"
sort -t$'\t' -k1,1 -rn "$log" | sed "s|$build/||" | head -${TOP:-40}
awk -F'\t' '{s += $1; if ($3 > m) {m = $3; w = $2}} END {printf "total: %.0f CPU seconds in %d compiler calls; largest peak memory %d MB (%s)\n", s, NR, m, w}' "$log"
