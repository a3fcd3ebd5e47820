#!/usr/bin/env bash
# Checkpoint and resume (issue 17 part 3): `kushner compare` (PF on, 2000 members) killed with SIGKILL at three
# points, each time resumed with `kushner resume DIR`, writes every output file byte for byte as a run never
# stopped (serial, and OpenMP on 2 threads); SIGINT and SIGTERM save a checkpoint and stop cleanly; a
# checkpoint that is missing, truncated, corrupt, of another version or of a changed model file is refused
# with one line and leaves the results already written intact.
# KUSHNER_CHECKPOINT_BACKENDS (default "serial openmp") names the backends of the SIGKILL runs (the first also
# runs the rest); KUSHNER_CHECKPOINT_TOLERANCE, when set, lets numbers differ by that much relative instead of
# requiring the same bytes, and KUSHNER_CHECKPOINT_EVERY (default 0.05 s) how often the runs save (a GPU runs
# the 400 steps in well under a second: 0 there).
set -eu
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'kill -9 $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
export OMP_PROC_BIND=false

# PF and every filter of the sine model, traced members and a density snapshot (recorder state), 400 steps,
# a checkpoint every 0.05 s (the uninterrupted run has it too: the command line is in every file).
args=(compare --model sine --members 2000 --particles 64 --T 0.8 --dt 2e-3 --output-points 40
      --enkbf-particles 10 --density-times 0.2,0.6 --no-plots --quiet --seed 7 --checkpoint-every "${KUSHNER_CHECKPOINT_EVERY:-0.05}")

# own_lines FILE: FILE without the warning Kokkos prints on a GPU newer than the build's PTX (not kushner's).
own_lines() { grep -v '^Kokkos::Cuda::initialize WARNING' "$1" || true; }

# checkpoint_step DIR: the step of DIR's checkpoint (0 when there is none yet).
checkpoint_step() {
  local step
  step=$(sed -n 2p "$1/checkpoint.kushner" 2>/dev/null | grep -o '"step":[0-9]*' | cut -d: -f2) || true
  echo "${step:-0}"
}

# signal_after_step SIGNAL DIR STEP PID: send SIGNAL to PID once DIR's checkpoint is past STEP (fails if PID
# ends first).
signal_after_step() {
  local signal=$1 dir=$2 step=$3 pid=$4
  while [ "$(checkpoint_step "$dir")" -lt "$step" ]; do
    kill -0 "$pid" 2>/dev/null || fail "the run ended before its checkpoint passed step $step"
    sleep 0.02
  done
  kill -s "$signal" "$pid"
}
kill_after_step() {
  signal_after_step KILL "$@"
  wait "$3" 2>/dev/null || true
}

# same_numbers A B TOLERANCE: the same text with every number equal to TOLERANCE relative; prints the largest
# relative difference.
same_numbers() {
  python3 - "$1" "$2" "$3" <<'PY'
import re, sys
number = re.compile(rb"-?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|nan|inf)")
a, b = (open(f, "rb").read() for f in sys.argv[1:3])
if number.sub(b"#", a) != number.sub(b"#", b):
    print("text differs"); sys.exit(1)
worst = 0.0
for x, y in zip(map(float, number.findall(a)), map(float, number.findall(b))):
    if x != y and not (x != x and y != y):
        worst = max(worst, abs(x - y) / max(abs(x), abs(y)))
print(f"largest relative difference {worst:.3g}")
sys.exit(0 if worst <= float(sys.argv[3]) else 1)
PY
}

# without_timing FILE: FILE without its wall times (summary.json's "timing" entry, report.md's "- wall time:" line),
# which differ from run to run, as the tests of determinism leave them out.
without_timing() { sed -e '/^  "timing": {/,/^  },\{0,1\}$/d' -e '/^- wall time: /d' "$1"; }

# same_files A B: the same file names and bytes, wall times aside (numbers to KUSHNER_CHECKPOINT_TOLERANCE when set).
same_files() {
  [ "$(cd "$1" && ls)" = "$(cd "$2" && ls)" ] || fail "files differ: $(cd "$1" && ls | tr '\n' ' ') vs $(cd "$2" && ls | tr '\n' ' ')"
  local f
  for f in "$1"/*; do
    cmp -s <(without_timing "$f") <(without_timing "$2/$(basename "$f")") && continue
    [ -n "${KUSHNER_CHECKPOINT_TOLERANCE:-}" ] || fail "$(basename "$f") differs after resuming"
    same_numbers "$f" "$2/$(basename "$f")" "$KUSHNER_CHECKPOINT_TOLERANCE" ||
      fail "$(basename "$f") differs after resuming beyond $KUSHNER_CHECKPOINT_TOLERANCE"
  done
}

backends=(${KUSHNER_CHECKPOINT_BACKENDS:-serial openmp})
for backend in "${backends[@]}"; do
  export KUSHNER_BACKEND=$backend OMP_NUM_THREADS=2
  # The uninterrupted run, in the same directory name as the stopped one (the command line is in every file).
  "$kushner" "${args[@]}" --out "$work/run" > /dev/null
  mv "$work/run" "$work/reference-$backend"

  "$kushner" "${args[@]}" --out "$work/run" > /dev/null 2>&1 &
  kill_after_step "$work/run" 60 $!
  for stop in 160 300; do
    "$kushner" resume "$work/run" > /dev/null 2>&1 &
    kill_after_step "$work/run" "$stop" $!
  done
  [ -e "$work/run/checkpoint.kushner" ] || fail "no checkpoint after the third kill"
  "$kushner" resume "$work/run" > "$work/resume.out" 2> "$work/resume.err" || fail "resume: $(cat "$work/resume.err")"
  [ ! -e "$work/run/checkpoint.kushner" ] || fail "the checkpoint is left after the run finished"
  same_files "$work/reference-$backend" "$work/run"
  echo "ok: $backend: SIGKILL at three checkpoints, resumed: every file byte for byte"
  rm -rf "$work/run"
done
# SIGINT and SIGTERM: a checkpoint, one line, exit 128 + signal; resuming finishes the same run.
first=${backends[0]}
export KUSHNER_BACKEND=$first
for signal in INT TERM; do
  "$kushner" "${args[@]}" --out "$work/run" > /dev/null 2> "$work/signal.err" &
  pid=$!
  signal_after_step $signal "$work/run" 100 $pid
  set +e
  wait $pid
  rc=$?
  set -e
  want=$([ $signal = INT ] && echo 130 || echo 143)
  [ "$rc" -eq "$want" ] || fail "SIG$signal: exit $rc (want $want): $(cat "$work/signal.err")"
  message=$(own_lines "$work/signal.err")
  grep -q "^kushner: stopped by SIG$signal after step [0-9]* of 400; checkpoint written: continue with: kushner resume " \
    <<<"$message" || fail "SIG$signal message: $message"
  [ "$(wc -l <<<"$message")" -eq 1 ] || fail "SIG$signal: stderr is not one line: $message"
  "$kushner" resume "$work/run" > /dev/null
  same_files "$work/reference-$first" "$work/run"
  echo "ok: SIG$signal: checkpoint, exit $rc, resumed to the same files"
  rm -rf "$work/run"
done

# refused_resume "message fragment" DIR: exit 2, one line containing the fragment, DIR's files unchanged.
refused_resume() {
  local fragment=$1 dir=$2 before
  before=$(cd "$dir" && ls -l --time-style=+%s.%N | sha256sum)
  run_kushner "$work/r" resume "$dir"
  [ "$rc" -eq 2 ] || fail "resume exit $rc (want 2): $(cat "$work/r.err")"
  local message
  message=$(own_lines "$work/r.err")
  [ "$(wc -l <<<"$message")" -eq 1 ] || fail "resume: stderr is not one line: $message"
  grep -qF -- "$fragment" <<<"$message" || fail "resume message: $message (want: $fragment)"
  [ "$before" = "$(cd "$dir" && ls -l --time-style=+%s.%N | sha256sum)" ] || fail "a refused resume changed $dir"
  echo "ok: refused: $message"
}

# A run stopped with a checkpoint beside the results of an earlier run in the same directory.
mkdir -p "$work/run"
cp "$work/reference-$first/"* "$work/run/"
"$kushner" "${args[@]}" --out "$work/run" > /dev/null 2>&1 &
pid=$!
signal_after_step INT "$work/run" 100 $pid
wait $pid || true
[ -e "$work/run/checkpoint.kushner" ] || fail "SIGINT left no checkpoint"
cp "$work/run/checkpoint.kushner" "$work/good.kushner"

refused_resume "resume: no checkpoint in '$work/reference-$first'" "$work/reference-$first"
# A new run into a directory that holds an unfinished run's checkpoint.
run_kushner "$work/r" "${args[@]}" --out "$work/run"
[ "$rc" -eq 2 ] && grep -q "holds the checkpoint of an unfinished run" "$work/r.err" ||
  fail "a new run over a checkpoint: exit $rc, $(cat "$work/r.err")"
head -c 2000 "$work/good.kushner" > "$work/run/checkpoint.kushner"
refused_resume "truncated" "$work/run"
cp "$work/good.kushner" "$work/run/checkpoint.kushner"
size=$(stat -c %s "$work/run/checkpoint.kushner")
# One byte near the end, inverted (writing a fixed byte changed nothing where the byte was that already: a run
# stopped at step 119 had 0x55 there, and its resume rightly succeeded).
byte=$(od -An -tu1 -j $((size - 100)) -N 1 "$work/run/checkpoint.kushner" | tr -d ' ')
printf "\\x$(printf '%02x' $((byte ^ 0xff)))" | dd of="$work/run/checkpoint.kushner" bs=1 seek=$((size - 100)) conv=notrunc status=none
refused_resume "corrupt (checksum mismatch)" "$work/run"
sed '2s/"version":"[^"]*"/"version":"kushner 0.0.1 (git 000000000000)"/' "$work/good.kushner" > "$work/run/checkpoint.kushner"
refused_resume "written by kushner 0.0.1 (git 000000000000); this is kushner" "$work/run"
echo "junk" > "$work/run/checkpoint.kushner"
refused_resume "not a kushner checkpoint" "$work/run"
for f in summary.json timeseries.csv trajectories.csv density.csv; do
  cmp -s "$work/reference-$first/$f" "$work/run/$f" || fail "refused resumes changed $f"
done
rm -rf "$work/run"

# The bank alone on the host from 4096 members takes its steps in segments (FilterBank::start_segment), so its
# checkpoints fall between segments: killed at one, stopped by SIGINT at another, resumed, the same files.
segments=(compare --model sine --filters EKF,QLF,UKF,EnKBF --enkbf-particles 20 --members 5000 --T 2 --dt 1e-3
          --output-points 300 --trajectory-members 0,4500 --no-plots --quiet --seed 8 --checkpoint-every 0.05)
export KUSHNER_BACKEND=openmp OMP_NUM_THREADS=2
"$kushner" "${segments[@]}" --out "$work/run" > /dev/null
mv "$work/run" "$work/segments-reference"
"$kushner" "${segments[@]}" --out "$work/run" > /dev/null 2>&1 &
kill_after_step "$work/run" 500 $!
"$kushner" resume "$work/run" > /dev/null 2>&1 &
pid=$!
signal_after_step INT "$work/run" 1200 $pid
wait $pid || true
[ -e "$work/run/checkpoint.kushner" ] || fail "segments: SIGINT left no checkpoint"
"$kushner" resume "$work/run" > /dev/null
same_files "$work/segments-reference" "$work/run"
echo "ok: segments: SIGKILL and SIGINT at checkpoints between segments, resumed: every file byte for byte"
rm -rf "$work/run"

# A model file changed between the stop and the resume: the state is of another model.
model="$work/linear2.toml"
cp "$(dirname "$0")/../../models/examples/linear2.toml" "$model"
"$kushner" filter --model-file "$model" --members 300 --T 2 --dt 1e-3 --filters KB,EKF,PF --particles 64 --quiet \
  --out "$work/file-run" --checkpoint-every 0.01 > /dev/null 2>&1 &
kill_after_step "$work/file-run" 100 $!
sed -i 's/-1\.0/-1.5/' "$model"
refused_resume "written for another model or option set" "$work/file-run"
echo "ok: checkpoint and resume"
