#!/usr/bin/env bash
# MPI ensembles: `mpirun -np R kushner ...` for R = 1, 2, 3 (oversubscribed: CI has 2 cores) writes the same
# bytes as a plain run, in every file of simulate, filter, compare and control. The members are split at block
# boundaries of 256, so 700 members give 3 ranks one block each and 2 ranks shares of 256 and 444; compare's
# traced members (the first, whose density is taken, too) and control's traced member sit on the last rank.
# 40 members (one block) leave the first ranks with none.
# summary.json is compared byte for byte with its "backend" entry (which records ranks and threads) and its
# "timing" entry (wall times) taken out, report.md without its "- wall time:" line.
# An error on rank 0 ends every rank with one line and exit 2.
set -euo pipefail
kushner=$1
mpirun=$2
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1 OMP_PROC_BIND=false
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # CI containers run as root
mpi=("$mpirun" -q --oversubscribe --bind-to none)

without_backend() { sed -e '/^  "backend": {/,/^  },\{0,1\}$/d' -e '/^  "timing": {/,/^  },\{0,1\}$/d' "$1"; }
without_timing() { sed '/^- wall time: /d' "$1"; }

# check NAME ARGS...: a plain run and mpirun -np 1, 2, 3 of `kushner ARGS --out out`, every file compared.
check() {
  local name=$1; shift
  (cd "$work" && "$kushner" "$@" --out out --quiet >/dev/null) || fail "$name: the plain run failed"
  mv "$work/out" "$work/$name-plain"
  local files
  files=$(cd "$work/$name-plain" && ls)
  for ranks in 1 2 3; do
    local dir="$work/$name-np$ranks"
    # A bound on the time: ranks that call different collectives wait for each other forever.
    (cd "$work" && timeout 300 "${mpi[@]}" -np "$ranks" "$kushner" "$@" --out out --quiet >"$dir.log" 2>&1) ||
      fail "$name: mpirun -np $ranks failed or hung: $(tail -n 3 "$dir.log")"
    mv "$work/out" "$dir"
    [ "$(cd "$dir" && ls)" = "$files" ] || fail "$name: -np $ranks wrote $(cd "$dir" && ls | xargs) instead of $(xargs <<<"$files")"
    for f in $files; do
      if [ "$f" = summary.json ]; then
        cmp -s <(without_backend "$work/$name-plain/$f") <(without_backend "$dir/$f") ||
          fail "$name: summary.json differs beyond its backend with -np $ranks: $(diff <(without_backend "$work/$name-plain/$f") <(without_backend "$dir/$f") | head -n 4 | xargs)"
        if [ "$ranks" -gt 1 ]; then
          grep -q "\"ranks\": $ranks" "$dir/$f" || fail "$name: summary.json of -np $ranks does not record $ranks ranks"
        fi
      else
        cmp -s <(without_timing "$work/$name-plain/$f") <(without_timing "$dir/$f") || fail "$name: $f differs with -np $ranks"
      fi
    done
  done
  echo "ok: $name: the same bytes plain and with mpirun -np 1, 2, 3 ($(xargs <<<"$files"))"
}

check simulate simulate --model cubic-oscillator --members 700 --T 1 --dt 1e-2 --seed 3
check filter filter --model sine --filters all --members 700 --T 0.3 --dt 1e-2 --particles 64 --enkbf-particles 16 \
  --output-points 6 --seed 5
check compare compare --model cubic-oscillator --filters EKF,QLF,UKF,PF --members 700 --T 0.3 --dt 1e-2 \
  --particles 64 --trajectory-members 650,0,300 --density-times 0.1,0.3 --output-points 6 --no-plots --seed 6
check control control --model sine --members 600 --T 0.3 --dt 1e-2 --particles 64 --trace-member 550 --seed 4 \
  --controllers NONE@state,LQR@EKF,LQR@PF,ASRE@ASRE --cost Q=1 --no-plots
# The bank alone on the host from 4096 members takes its steps in segments (FilterBank::start_segment): 5000 members
# are 20 blocks (shares of 6, 7, 7 over 3 ranks), the traced members on the first, middle and last rank.
check segments compare --model sine --filters EKF,SOF,QLF,KBL --members 5000 --T 0.3 --dt 1e-2 --output-points 7 \
  --trajectory-members 4999,0,2600 --no-plots --seed 12
# simulate from 4096 members steps 16 steps at a time (TruthBank::step_segment); 5000 members over 2 or 3 ranks are
# shares below that, a step at a time: the same bytes both ways.
check simulate-segments simulate --model cubic-oscillator --members 5000 --T 0.3 --dt 1e-2 --output-points 7 --seed 13
# Fewer blocks than ranks: 40 members are one block, which the last rank holds; rank 0 (the writer) and, with 3
# ranks, rank 1 hold none. Every command with the particle filter, continuous and discrete time.
check few-compare compare --model sine --members 40 --T 0.2 --dt 1e-2 --particles 64 --enkbf-particles 16 \
  --output-points 3 --no-plots --seed 7
check few-control control --model sine --members 40 --T 0.2 --dt 1e-2 --particles 64 --no-plots --seed 8
check few-discrete filter --model clark-linear --filters all,EXACT --members 40 --particles 64 --T 5 --seed 9

# An error on rank 0 alone (only rank 0 opens --out) ends all ranks: one line, exit 2, nothing left running.
touch "$work/not-a-directory"
set +e
timeout 60 "${mpi[@]}" -np 2 "$kushner" simulate --members 600 --out "$work/not-a-directory" --quiet \
  >"$work/error.out" 2>"$work/error.err"
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "an error on rank 0 exited $rc, not 2: $(cat "$work/error.err")"
[ "$(grep -c . "$work/error.err")" -eq 1 ] || fail "an error on rank 0 printed more than one line: $(cat "$work/error.err")"
grep -q "^kushner: error: --out: .* exists and is not a directory" "$work/error.err" ||
  fail "unexpected error line: $(cat "$work/error.err")"
echo "ok: an error on rank 0 ends both ranks with one line and exit 2"
