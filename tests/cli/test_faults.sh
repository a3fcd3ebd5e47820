#!/usr/bin/env bash
# Faults of the machine and of the numbers (README, "Faults and what you see"): a full disk, a read-only output
# directory and too little memory each give one line "kushner: error: ..." on stderr and exit 2, leaving results
# already written as they were and no .tmp files; filters and particle filters pushed to divergence finish the
# run and are counted. (Bad input: test_bad_input.sh.) The disk cases need root (mount); they are skipped
# otherwise, and say so; a file-size limit (ulimit -f) stands in for a full disk for any user.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
mounted=()
cleanup() {
  for m in "${mounted[@]}"; do umount "$m" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

expect_fault() {  # expect_fault "expected message fragment" args...
  local expected=$1; shift
  run_kushner "$work/r" "$@"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  grep -q '^kushner: error: ' "$work/r.err" || fail "no 'kushner: error:' prefix for: $*: $(cat "$work/r.err")"
  grep -qF -- "$expected" "$work/r.err" || fail "message lacks '$expected' for: $*: $(cat "$work/r.err")"
  echo "ok: $(cat "$work/r.err")"
}
digest() { (cd "$1" && ls -a | md5sum && cat ./* | md5sum); }  # the names (no stray .tmp) and the contents
small=(--members 50 --T 0.1 --dt 0.01 --quiet)

# Too little memory: the particle bank (10^8 particles, 0.8 GB a copy) cannot be allocated under a 600 MB
# address-space limit (a limit makes malloc fail instead of waking the kernel's OOM killer; the check before
# allocation sees the machine's free memory, which the limit does not lower). AddressSanitizer reserves terabytes
# of address space for its shadow memory at start, so under it (tests/sanitize/run.sh) no limit can be set.
# A CUDA build's runtime cannot start under such a limit ("no usable GPU (cudaGetDeviceCount: out of memory)"), so
# there the GPU's own memory is the limit: a bank larger than any GPU's memory is refused before allocation.
if ldd "$kushner" 2>/dev/null | grep -q libasan; then
  echo "skipped: out of memory under an address-space limit (kushner is built with AddressSanitizer)"
elif [[ " $(built_backends) " == *" cuda "* ]]; then
  expect_fault "--members 40000: the run needs 298 GiB (filter bank 7.63 MiB per member), but cuda has " \
    filter --model sine --filters EnKBF --enkbf-particles 1000000 --members 40000 --T 0.01 --dt 0.01 \
    --out "$work/memory" --quiet
  [ ! -e "$work/memory" ] || fail "out of GPU memory: the refused run created its output directory"
else
  set +e
  (ulimit -v 600000 && exec "$kushner" filter --filters PF --members 1000 --particles 100000 --T 0.01 --dt 0.01 \
    --out "$work/memory" --quiet) >"$work/r.out" 2>"$work/r.err"
  rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "out of memory: exit $rc (want 2): $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "out of memory: stderr is not one line: $(cat "$work/r.err")"
  grep -qF "kushner: error: not enough memory: kushner::particles needs " "$work/r.err" ||
    fail "out of memory: $(cat "$work/r.err")"
  echo "ok: $(cat "$work/r.err")"
fi

# A full disk: a 64 KiB tmpfs holding an earlier run, then filled.
if [ "$(id -u)" -eq 0 ] && mkdir "$work/disk" && mount -t tmpfs -o size=64k tmpfs "$work/disk" 2>/dev/null; then
  mounted+=("$work/disk")
  "$kushner" simulate "${small[@]}" --out "$work/disk/run"
  before=$(digest "$work/disk/run")
  head -c 1M /dev/zero >"$work/disk/filler" 2>/dev/null || true  # fills it: head stops at "No space left"
  expect_fault "--out: cannot write '$work/disk/run/timeseries.csv': No space left on device" \
    simulate "${small[@]}" --dt 0.02 --out "$work/disk/run"
  expect_fault "No space left on device" compare --members 5 --T 0.1 --dt 0.01 --out "$work/disk/run"
  [ "$before" = "$(digest "$work/disk/run")" ] || fail "a full disk changed the results already written"
  # One page free: this run's timeseries.csv fits, its summary.json does not. Both or neither are written.
  rm "$work/disk/filler"
  head -c $((64 * 1024 - 3 * 4096)) /dev/zero >"$work/disk/filler"
  expect_fault "--out: cannot write '$work/disk/run/summary.json': No space left on device" \
    simulate "${small[@]}" --dt 0.02 --out "$work/disk/run"
  [ "$before" = "$(digest "$work/disk/run")" ] || fail "a half-written run changed the results already written"
  # The same directory read-only (a read-only mount: root writes through permissions).
  mount -o remount,ro "$work/disk"
  expect_fault "--out: directory '$work/disk/run' is not writable: Read-only file system" \
    simulate "${small[@]}" --out "$work/disk/run"
  expect_fault "--out: cannot create directory '$work/disk/new'" simulate "${small[@]}" --out "$work/disk/new"
  [ "$before" = "$(digest "$work/disk/run")" ] || fail "a read-only directory's results changed"
else
  echo "skip: the full-disk and read-only cases need root to mount a tmpfs"
fi

# A file-size limit (ulimit -f, any user; the full disk's stand-in where no tmpfs can be mounted): the write fails
# with "File too large" instead of SIGXFSZ killing the run mid-file and leaving a .tmp behind.
"$kushner" simulate "${small[@]}" --out "$work/limited"
before=$(digest "$work/limited")
set +e
(ulimit -f 1 && exec "$kushner" simulate --members 5 --T 1 --dt 0.01 --output-points 101 --quiet \
  --out "$work/limited") >"$work/r.out" 2>"$work/r.err"
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "file-size limit: exit $rc (want 2): $(cat "$work/r.err")"
[ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "file-size limit: stderr is not one line: $(cat "$work/r.err")"
grep -qF "kushner: error: --out: cannot write '$work/limited/timeseries.csv': File too large (files already there are unchanged)" \
  "$work/r.err" || fail "file-size limit: $(cat "$work/r.err")"
[ "$before" = "$(digest "$work/limited")" ] || fail "a file-size limit changed the results already written"
echo "ok: $(cat "$work/r.err")"

# A directory the user may not write (as root, run as nobody: root writes through permissions).
as_nobody=(setpriv --reuid=65534 --regid=65534 --clear-groups)
chmod 755 "$work"
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null && "${as_nobody[@]}" "$kushner" models >/dev/null 2>&1; then
  mkdir "$work/locked" && chown 65534 "$work/locked"
  "${as_nobody[@]}" "$kushner" simulate "${small[@]}" --out "$work/locked/run"
  before=$(digest "$work/locked/run")
  chmod a-w "$work/locked/run" "$work/locked"
  printf '#!/bin/sh\nexec setpriv --reuid=65534 --regid=65534 --clear-groups "%s" "$@"\n' "$kushner" >"$work/as-nobody"
  chmod 755 "$work/as-nobody"
  expect_fault_as_nobody() {
    local saved=$kushner
    kushner=$work/as-nobody
    expect_fault "$@"
    kushner=$saved
  }
  expect_fault_as_nobody "--out: directory '$work/locked/run' is not writable: Permission denied" \
    simulate "${small[@]}" --dt 0.02 --out "$work/locked/run"
  expect_fault_as_nobody "--out: cannot create directory '$work/locked/new': Permission denied" \
    simulate "${small[@]}" --out "$work/locked/new"
  [ "$before" = "$(digest "$work/locked/run")" ] || fail "an unwritable directory's results changed"
  chmod u+w "$work/locked/run" "$work/locked"
elif [ "$(id -u)" -eq 0 ]; then
  echo "skip: the unwritable-directory case needs setpriv to run as nobody (test_bad_input.sh runs it as a user)"
fi

# Divergence: the runs finish (exit 0) and count what diverged.
summary_check() {  # summary_check DIR PYTHON-EXPRESSION-OVER-s: fails the test unless it holds
  python3 -c 'import json, sys; s = json.load(open(sys.argv[1] + "/summary.json")); sys.exit(0 if eval(sys.argv[2]) else 1)' \
    "$1" "$2" || fail "$1/summary.json: not $2: $(cat "$1/summary.json")"
}
# The hard sine regime: r = 4, x(0) ~ N(0, 9) (truths and filters).
"$kushner" filter --model sine --set r=4 --set x0_mean=0 --set x0_cov=9 --set prior_mean=0 --set prior_cov=9 \
  --members 50 --particles 128 --T 10 --dt 0.01 --out "$work/sine" --quiet
summary_check "$work/sine" 'all(isinstance(f["diverged"], int) and f["diverged"] + f["members_scored"] == 50 for f in s["filters"].values())'
echo "ok: sine r = 4, x(0) ~ N(0, 9): finished; diverged $(python3 -c 'import json, sys; print({k: f["diverged"] for k, f in json.load(open(sys.argv[1]))["filters"].items()})' "$work/sine/summary.json")"
# The cubic oscillator from the printed (15, 10): every truth escapes (t = 0.34), so no member is scored.
"$kushner" filter --model cubic-oscillator --set x0_mean=15,10 --members 20 --particles 128 --T 1 --dt 0.002 \
  --out "$work/cubic" --quiet
summary_check "$work/cubic" 's["truths_escaped"] == 20 and all(f["members_scored"] == 0 and f["rmse_truth"] is None for f in s["filters"].values())'
echo "ok: cubic oscillator from (15, 10): finished, truths_escaped 20"
# A particle filter whose weights all underflow. r = 1e-154: the log-likelihood of every particle is -inf, the
# member's weights are all zero, and it is reported as diverged (non-finite); the others' rmse_ref leaves the
# members whose reference diverged out (all of them here: no rmse_ref rather than one against a frozen mean).
pf=(--model sine --filters EKF,PF --set x0_mean=0 --set x0_cov=0 --set prior_mean=3 --set prior_cov=0.01 --members 20
  --particles 64 --T 1 --dt 0.01 --quiet)
"$kushner" filter "${pf[@]}" --set r=1e-154 --out "$work/pf-dead"
summary_check "$work/pf-dead" 's["filters"]["PF"]["diverged_non_finite"] == 20 and s["filters"]["EKF"]["diverged"] == 0 and s["filters"]["EKF"]["rmse_ref"] is None'
echo "ok: PF weights all zero (r = 1e-154): PF diverged_non_finite 20, EKF unscored against it"
# r = 1e-152: the likelihoods underflow as numbers but not as logarithms: the best particle takes the weight
# (ESS 1), resampling recovers, and every member is scored.
"$kushner" filter "${pf[@]}" --set r=1e-152 --out "$work/pf-collapse"
summary_check "$work/pf-collapse" 's["filters"]["PF"]["diverged"] == 0 and s["filters"]["PF"]["members_scored"] == 20 and s["filters"]["PF"]["estimator"]["mean_ess"] < 1.5'
echo "ok: PF weights underflowing (r = 1e-152): recovers (ESS 1), no member lost"
echo "all faults handled"
