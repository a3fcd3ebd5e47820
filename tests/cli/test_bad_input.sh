#!/usr/bin/env bash
# Bad input: one line on stderr starting "kushner: error:", exit code 2, no partial files, and results a
# previous run wrote are left untouched.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'chmod -R u+w "$work"; rm -rf "$work"' EXIT

expect_refused() {  # expect_refused "expected message fragment" args...
  local expected=$1; shift
  run_kushner "$work/r" "$@"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  grep -q '^kushner: error: ' "$work/r.err" || fail "no 'kushner: error:' prefix for: $*"
  grep -qF -- "$expected" "$work/r.err" || fail "message lacks '$expected' for: $*: $(cat "$work/r.err")"
  [ ! -s "$work/r.out" ] || fail "stdout not empty for: $*"
  echo "ok: $(cat "$work/r.err")"
}

fresh="$work/fresh"
expect_refused "unknown model 'sin' (known: benes, car, car-taylor3, clark-linear, cubic-oscillator, linear, ou, sine, terpolymer)" simulate --model sin --out "$fresh"
expect_refused "--dt: must be positive (got 0)" simulate --dt 0 --out "$fresh"
expect_refused "--dt: must be positive (got -1)" simulate --dt -1 --out "$fresh"
expect_refused "--members: must be positive (got 0)" simulate --members 0 --out "$fresh"
expect_refused "--T: must be a whole number of --dt steps" simulate --T 1 --dt 0.3 --out "$fresh"
expect_refused "--seed: must be in 0 .. 4294967295" simulate --seed -3 --out "$fresh"
expect_refused "prior_cov: not positive semidefinite (smallest eigenvalue -1)" simulate --set prior_cov=-1 --out "$fresh"
expect_refused "model 'sine' has no parameter 'qq'" simulate --set qq=1 --out "$fresh"
expect_refused "--members" simulate --members lots --out "$fresh"
printf 'members = 10\nthis line is not toml or ini\n' >"$work/bad.toml"
expect_refused "bad.toml" simulate --config "$work/bad.toml" --out "$fresh"
printf 'members = 10\nnot_an_option = 3\n' >"$work/extra.toml"
expect_refused "not_an_option" simulate --config "$work/extra.toml" --out "$fresh"
expect_refused "missing.toml" simulate --config "$work/missing.toml" --out "$fresh"
# 1e11 particles: refused before any allocation, with the size needed (this machine has far less than 2.5 TiB).
expect_refused "--members 100000, --particles 1000000: the run needs 2.55 TiB (filter bank" \
  compare --members 100000 --particles 1000000 --filters EKF,PF --out "$fresh"
[ ! -e "$fresh" ] || fail "a refused run created $fresh"

touch "$work/a-file"
expect_refused "--out: cannot create directory" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/a-file/sub"
expect_refused "exists and is not a directory" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/a-file"
if [ "$(id -u)" -ne 0 ]; then  # root writes anywhere, so the permission case only means something for users
  mkdir "$work/locked" && chmod a-w "$work/locked"
  expect_refused "not writable" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/locked"
fi

# Results already written survive a refused run into the same directory.
"$kushner" simulate --members 50 --T 0.1 --dt 0.01 --out "$work/kept" --quiet
before=$(cat "$work/kept"/* | md5sum)
expect_refused "--dt: must be positive" simulate --members 50 --dt -0.01 --out "$work/kept"
expect_refused "unknown model" simulate --model nope --out "$work/kept"
[ "$before" = "$(cat "$work/kept"/* | md5sum)" ] || fail "a refused run changed results already written"
[ "$(ls "$work/kept" | wc -l)" -eq 2 ] || fail "stray files in $work/kept: $(ls "$work/kept")"
echo "all bad-input cases refused cleanly"
