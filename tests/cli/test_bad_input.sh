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
expect_refused "unknown model 'sin' (known: benes, car, car-taylor3, clark-linear, clark-quintic, cubic-oscillator, cubic-sensor, linear, linear-discrete, ou, pendulum, range-bearing, sine, terpolymer)" simulate --model sin --out "$fresh"
expect_refused "--dt: must be positive (got 0)" simulate --dt 0 --out "$fresh"
expect_refused "--dt: must be positive (got -1)" simulate --dt -1 --out "$fresh"
expect_refused "--members: must be positive (got 0)" simulate --members 0 --out "$fresh"
expect_refused "--T: must be a whole number of --dt steps" simulate --T 1 --dt 0.3 --out "$fresh"
expect_refused "--seed: must be in 0 .. 4294967295" simulate --seed -3 --out "$fresh"
expect_refused "prior_cov: not positive semidefinite (smallest eigenvalue -1)" simulate --set prior_cov=-1 --out "$fresh"
expect_refused "model 'sine' has no parameter 'qq'" simulate --set qq=1 --out "$fresh"
expect_refused "--members: expected a whole number (got 'lots')" simulate --members lots --out "$fresh"
expect_refused "--members: expected a whole number (got '1.5')" simulate --members 1.5 --out "$fresh"  # 1e3 is 1000
expect_refused "--particles: out of range (got '1e30')" filter --particles 1e30 --out "$fresh"
expect_refused "--trajectory-members: expected a whole number (got 'x')" compare --trajectory-members 0,x --out "$fresh"
# Named in the order given (CLI11 2.3's own message joined them backwards: "4 --b2 3 --bogus").
expect_refused "unexpected arguments: --bogus 3 --b2 4 (\`kushner simulate --help\` lists the options)" \
  simulate --bogus 3 --b2 4 --out "$fresh"
expect_refused "unexpected argument: extra" simulate extra --out "$fresh"
printf 'members = 10\nthis line is not toml or ini\n' >"$work/bad.toml"
expect_refused "bad.toml" simulate --config "$work/bad.toml" --out "$fresh"
printf 'members = 10\nnot_an_option = 3\n' >"$work/extra.toml"
expect_refused "not_an_option" simulate --config "$work/extra.toml" --out "$fresh"
expect_refused "missing.toml" simulate --config "$work/missing.toml" --out "$fresh"
# NaN or Inf in any parameter or option.
expect_refused "--set q: 'nan' is not finite" simulate --set q=nan --out "$fresh"
expect_refused "--set x0_mean: 'inf' is not finite" filter --set x0_mean=inf --out "$fresh"
expect_refused "--set x0_cov: '-inf' is not finite" simulate --set x0_cov=-inf --out "$fresh"
expect_refused "--dt: must be positive (got nan)" simulate --dt nan --out "$fresh"
expect_refused "--T: must be positive (got inf)" simulate --T inf --out "$fresh"
expect_refused "--ess-threshold: must be in [0, 1] (got nan)" filter --ess-threshold nan --out "$fresh"
expect_refused "--set Q: 'nan' is not finite" control --cost Q=nan --out "$fresh"
expect_refused "--ukf-alpha: must be positive (got nan)" filter --filters UKF --ukf-alpha nan --out "$fresh"
expect_refused "--asre-tolerance: must be positive (got inf)" filter --filters ASRE --asre-tolerance inf --out "$fresh"
printf 'T = 1\ndt = nan\n' >"$work/nan.toml"
expect_refused "--dt: must be positive (got nan)" simulate --config "$work/nan.toml" --out "$fresh"
sed 's/^x0_mean = .*/x0_mean = [nan, 0.0]/' "$(dirname "$0")/../../models/examples/linear2.toml" >"$work/nan-model.toml"
expect_refused "nan-model.toml: initial.x0_mean[0]: not finite" simulate --model-file "$work/nan-model.toml" --out "$fresh"
# Found by fuzzing (tests/fuzz/regressions/): a list of blanks selected no filter and ran; a blank key; a model
# file with a code point that sends toml++ 3.3.0 into undefined behaviour.
expect_refused "--filters: empty name in ' '" filter --filters ' ' --out "$fresh"
expect_refused "--filters: empty name in 'PF, '" filter --filters 'PF, ' --out "$fresh"
expect_refused "--controllers: empty name in 'LQR@state,'" control --controllers 'LQR@state,' --out "$fresh"
expect_refused "--step-pairs always: a closed loop's particle filter takes one step at a time" \
  control --controllers LQR@PF --step-pairs always --out "$fresh"
expect_refused "--set: expected key=value, got ' =1'" simulate --set ' =1' --out "$fresh"
printf 'state_dim = 1\n\xcf\x83 = 1\n' >"$work/sigma.toml"
expect_refused "sigma.toml: line 2, column 1: U+03C3 is a character the TOML reader of this build (toml++ 3.3.0) mishandles" \
  simulate --model-file "$work/sigma.toml" --out "$fresh"
# Sizes whose product overflows the index type (int): members, members x particles, steps.
expect_refused "--members: at most 2147483647 (got 4000000000)" simulate --members 4000000000 --out "$fresh"
expect_refused "--particles: --members x --particles must be at most 2147483647, the particle filter's index range (got 100000 x 30000 = 3000000000)" \
  filter --filters EKF,PF --members 100000 --particles 30000 --out "$fresh"
expect_refused "--dt: too small for --T (1e+24 steps; at most 4e9)" simulate --T 1e12 --dt 1e-12 --out "$fresh"
# More output points than time points; a --trajectory-members index out of range.
expect_refused "--output-points: must be at most T/dt + 1 = 11, the time points 0, dt, ..., T (got 100)" \
  simulate --T 0.1 --dt 0.01 --output-points 100 --out "$fresh"
printf 'T = 0.1\ndt = 0.01\noutput-points = 12\n' >"$work/points.toml"
expect_refused "--output-points: must be at most T/dt + 1 = 11" compare --config "$work/points.toml" --out "$fresh"
expect_refused "--trajectory-members: member 7 is not in 0 .. 4" compare --members 5 --trajectory-members 0,7 --out "$fresh"
expect_refused "--trajectory-members: member -1 is not in 0 .. 4" compare --members 5 --trajectory-members -1 --out "$fresh"
# Banks that cannot fit: refused before any allocation, with the bytes they need (2e9 particles of a 3-D model,
# 60 B each; not checked on a machine with more than 100 GiB available).
if [ "$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo)" -lt $((100 * 1024 * 1024)) ]; then
  expect_refused "--members 2000, --particles 1000000: the run needs 113 GiB (filter bank 331 B per member, particle filter 60 B per particle)" \
    compare --model linear --set dim=3 --members 2000 --particles 1000000 --filters EKF,PF --out "$fresh"
  # A filter's own state counts too: EnKBF's ensembles, 10^6 particles of 8 B per member (before: an allocation
  # failure after the run had started).
  expect_refused "--members 20000: the run needs 149 GiB (filter bank 7.63 MiB per member)" \
    filter --model sine --filters EnKBF --enkbf-particles 1000000 --members 20000 --out "$fresh"
else
  echo "note: more than 100 GiB available: the memory refusal is not checked here"
fi
[ ! -e "$fresh" ] || fail "a refused run created $fresh"

touch "$work/a-file"
expect_refused "--out: cannot create directory" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/a-file/sub"
expect_refused "exists and is not a directory" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/a-file"
if [ "$(id -u)" -ne 0 ]; then  # root writes anywhere, so the permission case only means something for users
  mkdir "$work/locked" && chmod a-w "$work/locked"
  expect_refused "not writable" simulate --members 10 --T 0.1 --dt 0.01 --out "$work/locked"
fi

# The default --output-points (200) is capped at the time points quietly; as many as there are is fine.
"$kushner" simulate --members 5 --T 0.1 --dt 0.01 --output-points 11 --out "$work/points" --quiet
[ "$(grep -vc '^#' "$work/points/timeseries.csv")" -eq 12 ] || fail "--output-points 11 did not give 11 rows"

# Results already written survive a refused run into the same directory.
"$kushner" simulate --members 50 --T 0.1 --dt 0.01 --out "$work/kept" --quiet
before=$(cat "$work/kept"/* | md5sum)
expect_refused "--dt: must be positive" simulate --members 50 --dt -0.01 --out "$work/kept"
expect_refused "unknown model" simulate --model nope --out "$work/kept"
expect_refused "--output-points: must be at most" simulate --members 50 --T 0.1 --dt 0.01 --output-points 12 --out "$work/kept"
[ "$before" = "$(cat "$work/kept"/* | md5sum)" ] || fail "a refused run changed results already written"
[ "$(ls "$work/kept" | wc -l)" -eq 2 ] || fail "stray files in $work/kept: $(ls "$work/kept")"
echo "all bad-input cases refused cleanly"
