#!/usr/bin/env bash
# `kushner control`: artefacts, the same bytes on 1 and 2 threads and on serial (host backends: host_backend in
# lib.sh; a CUDA build's default is left to tests/cli/test_filter_determinism.sh's tolerance), every controller's entry in
# summary.json, the HJB reference below the controllers, and bad input refused with one line, exit 2, nothing
# written.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python=/usr/bin/python3
[ -x "$python" ] || python=python3

host=$(host_backend)
args=(control --model sine --members 300 --T 1 --dt 1e-2 --particles 128 --seed 4
      --controllers NONE@state,LQR@state,LQR@EKF,LQR@PF,ASRE@ASRE,HJB@state --cost Q=1 --cost F=2 --cost R=0.5)
KUSHNER_BACKEND=$host OMP_NUM_THREADS=2 run_kushner "$work/a" "${args[@]}" --out "$work/a" --quiet
[ "$rc" -eq 0 ] || fail "control failed: $(cat "$work/a.err")"
for f in summary.json timeseries.csv report.md; do [ -s "$work/a/$f" ] || fail "control did not write $f"; done
if can_draw_figures; then
  for f in control_paths ranking running_cost; do [ -s "$work/a/$f.png" ] || fail "control did not draw $f.png"; done
fi
KUSHNER_BACKEND=$host OMP_NUM_THREADS=1 run_kushner "$work/b" "${args[@]}" --out "$work/b" --quiet --no-plots
[ "$rc" -eq 0 ] || fail "control (1 thread) failed: $(cat "$work/b.err")"
# Line 1 is the comment with the command (its --out differs); every number after it must be the same.
cmp -s <(tail -n +2 "$work/a/timeseries.csv") <(tail -n +2 "$work/b/timeseries.csv") ||
  fail "timeseries.csv differs between 1 and 2 threads"
KUSHNER_BACKEND=serial run_kushner "$work/c" "${args[@]}" --out "$work/c" --quiet --no-plots
[ "$rc" -eq 0 ] || fail "control (serial) failed: $(cat "$work/c.err")"
cmp -s <(tail -n +2 "$work/a/timeseries.csv") <(tail -n +2 "$work/c/timeseries.csv") ||
  fail "timeseries.csv differs between $host and serial"

"$python" - "$work/a/summary.json" "$work/b/summary.json" <<'PY' || fail "summary.json checks failed"
import json, math, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
names = ["NONE@state", "LQR@state", "LQR@EKF", "LQR@PF", "ASRE@ASRE", "HJB@state"]
assert a["controller_order"] == names, a["controller_order"]
for n in names:
    c = a["controllers"][n]
    for k in ("J", "J_se", "J_gap", "J_gap_se", "control_energy", "terminal_mean", "diverged"):
        assert k in c, (n, k)
    assert c["J"] == b["controllers"][n]["J"], (n, "J differs between 1 and 2 threads")
    assert c["members_scored"] == 300, (n, c["members_scored"])
ref = a["reference"]
assert ref["kind"] == "hjb" and ref["J"] > 0, ref
for n in names:
    c = a["controllers"][n]
    # No controller beats the full-information optimum by more than 3 standard errors (plus J*'s own error).
    assert c["J"] > ref["J"] - 3 * c["J_se"] - ref["error"], (n, c["J"], c["J_se"], ref)
assert a["controllers"]["NONE@state"]["control_energy"] == 0
assert a["controllers"]["LQR@state"]["J"] < a["controllers"]["NONE@state"]["J"]
assert a["cost"]["F"] == [[2.0]] and a["cost"]["R"] == [[0.5]]
print("summary ok: J* =", ref["J"], {n: round(a["controllers"][n]["J"], 4) for n in names})
PY

# On a linear model every Gaussian filter is Kalman-Bucy, so the known input must reach each filter's own state
# exactly: LQR@UKF and ASRE@ASRE (its iterates) equal LQG; LQR@EnKBF (its ensemble) runs beside them.
run_kushner "$work/lin" control --model linear --members 200 --T 1 --dt 1e-2 --seed 2 --no-plots --quiet \
  --controllers LQG,LQR@UKF,ASRE-C,LQR@EnKBF --cost 'Q=1,0;0,1' --out "$work/lin"
[ "$rc" -eq 0 ] || fail "control on the linear model failed: $(cat "$work/lin.err")"
"$python" - "$work/lin/summary.json" <<'PY' || fail "linear-model control checks failed"
import json, sys
s = json.load(open(sys.argv[1]))
c = s["controllers"]
for name in ("LQR@UKF", "ASRE-C"):
    assert abs(c[name]["J"] - c["LQG"]["J"]) <= 1e-10 * c["LQG"]["J"], (name, c[name]["J"], c["LQG"]["J"])
print("linear: LQG", c["LQG"]["J"], "UKF", c["LQR@UKF"]["J"], "ASRE-C", c["ASRE-C"]["J"], "EnKBF", c["LQR@EnKBF"]["J"])
PY

# Bad input: one line on stderr, exit 2, nothing written.
bad() {
  local name=$1 expect=$2; shift 2
  run_kushner "$work/bad" control --model sine --members 10 --T 0.1 --dt 1e-2 --out "$work/$name" "$@"
  [ "$rc" -eq 2 ] || fail "$name: exit $rc, expected 2 ($(cat "$work/bad.err"))"
  [ "$(wc -l <"$work/bad.err")" -eq 1 ] || fail "$name: not one line: $(cat "$work/bad.err")"
  grep -qF -- "$expect" "$work/bad.err" || fail "$name: '$(cat "$work/bad.err")' lacks '$expect'"
  [ ! -e "$work/$name" ] || fail "$name: wrote $work/$name"
}
bad q_indefinite "--cost Q: not positive semidefinite" --cost Q=-1
bad r_singular "--cost R: not positive definite" --cost R=0
bad f_shape "--cost F: expected a number" --cost F=1,2
bad cost_key "--cost P: unknown weight" --cost P=1
bad unknown_estimator "unknown estimator 'FOO'" --controllers LQR@FOO
bad unknown_law "unknown law 'MPC'" --controllers MPC@state
bad unsupported_law "law POLY3 cannot control model 'sine' (the drift is not a polynomial of degree <= 3)" --controllers POLY3@state
bad unsupported_estimator "estimator KB does not support model 'sine'" --controllers LQR@KB
bad not_a_controller "is not LAW@ESTIMATOR" --controllers LQR
bad twice "LQR@state is named twice" --controllers LQR@state,LQR@state
bad uncontrolled "has no control input" --model ou
bad trace "--trace-member: member 10 is not in 0 .. 9" --trace-member 10
bad reference_direct "--reference direct: the problem is stochastic" --reference direct
bad fp32 "--precision fp32: not available in control" --controllers LQR@PF --precision fp32
run_kushner "$work/bad" control --model terpolymer --controllers HJB@state --out "$work/hjb10"
[ "$rc" -eq 2 ] && [ ! -e "$work/hjb10" ] || fail "HJB on a 10-state model was not refused: $(cat "$work/bad.err")"

# `kushner controllers` lists laws, aliases and models.
run_kushner "$work/list" controllers
[ "$rc" -eq 0 ] && grep -q "POLYCTL  = POLY3@POLY3" "$work/list.out" && grep -q "car-taylor3" "$work/list.out" ||
  fail "kushner controllers: $(cat "$work/list.out" "$work/list.err")"
echo "control CLI ok"
