#!/usr/bin/env bash
# `--model-file`: a polynomial model read from a TOML file.
#  1. The example files equal to built-in models give the built-in's numbers with the same seed: every filter
#     both support, the particle filter and its rmse_ref, the grid filter (EXACT), and `simulate`. Bit for bit,
#     except QLF and MIXED on the cubic oscillator: the built-in takes their Gaussian expectation E_N[f] from
#     its hand-written closed form (seed 000 (6.14)) and its componentwise-power form, the file model from its
#     monomial moments (Isserlis): the same mathematics with different rounding (an ulp per step), so equal to
#     1e-10 relative (measured below); a coefficient changed by 1e-6 must show (checked below).
#  2. summary.json records the file and its coefficients; --set works on the initial law.
#  3. Bad input: malformed file, missing keys, wrong shapes, unknown keys, filters the coefficients rule out,
#     --model with --model-file: one line "kushner: error: FILE: KEY: ...", exit 2, nothing written, earlier
#     results untouched.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
examples="$(cd "$(dirname "$0")/../../models/examples" && pwd)"
work=$(mktemp -d)
trap 'chmod -R u+w "$work"; rm -rf "$work"' EXIT

# Bit for bit holds on the host backends (CPU builds compile with -ffp-contract=off); a GPU contracts a*b+c into
# FMAs wherever nvcc sees the pattern, which the built-in and the file model offer in different places.
backends=$(built_backends)
KUSHNER_BACKEND=$(host_backend)
export KUSHNER_BACKEND

# Compares two timeseries.csv files (simulate's truths): the largest relative difference, at most 1e-12.
compare_timeseries() {  # compare_timeseries A B
  python3 - "$@" <<'PY'
import sys
rows = [[l.rstrip("\n").split(",") for l in open(p) if not l.startswith("#")] for p in sys.argv[1:3]]
assert rows[0][0] == rows[1][0] and len(rows[0]) == len(rows[1]), "headers or lengths differ"
worst = max(abs(float(a) - float(b)) / max(abs(float(a)), abs(float(b)), 1e-300)
            for ra, rb in zip(rows[0][1:], rows[1][1:]) for a, b in zip(ra, rb))
print("  simulate, built-in vs file: largest relative difference %.3g" % worst)
sys.exit(worst > 1e-12)
PY
}

# Compares two summary.json files filter by filter: every metric equal, or within a relative tolerance for the
# filters named in LOOSE (name=tolerance).
compare_summaries() {  # compare_summaries A B LOOSE...
  python3 - "$@" <<'PY'
import json, math, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
loose = dict(kv.split("=") for kv in sys.argv[3:])
fa, fb = a["filters"], b["filters"]
assert a["filter_order"] == b["filter_order"], (a["filter_order"], b["filter_order"])
worst = {}
for name in a["filter_order"]:
    for key, va in fa[name].items():
        if key in ("estimator", "expectations", "gh_nodes", "iterations"):
            assert va == fb[name][key], (name, key, va, fb[name][key])
            continue
        vb = fb[name][key]
        if va == vb or (isinstance(va, float) and math.isnan(va) and math.isnan(vb)):
            continue
        tol = float(loose.get(name, 0))
        rel = abs(va - vb) / max(abs(va), abs(vb))
        worst[name] = max(worst.get(name, 0), rel)
        assert rel <= tol, "%s %s: %r vs %r (relative %.3g, tolerance %g)" % (name, key, va, vb, rel, tol)
print("  identical:", ", ".join(n for n in a["filter_order"] if n not in worst))
for n, r in worst.items():
    print("  %s: largest relative difference %.3g" % (n, r))
PY
}

# 1a. Cubic oscillator: every filter, PF as the reference, and EXACT (grid filter).
common=(--members 16 --particles 512 --T 0.6 --dt 1e-2 --seed 5 --output-points 6 --quiet --no-plots)
"$kushner" compare --model cubic-oscillator "${common[@]}" --out "$work/cubic-builtin"
"$kushner" compare --model-file "$examples/cubic_oscillator.toml" "${common[@]}" --out "$work/cubic-file"
echo "cubic oscillator, built-in vs file (compare, every filter and PF):"
compare_summaries "$work/cubic-builtin/summary.json" "$work/cubic-file/summary.json" QLF=1e-10 MIXED=1e-10 ||
  fail "the cubic-oscillator file does not give the built-in's numbers"
exact=(--filters EKF,POLY3,EXACT --members 3 --T 0.1 --dt 1e-2 --seed 5 --output-points 2 --quiet)
"$kushner" filter --model cubic-oscillator "${exact[@]}" --out "$work/exact-builtin"
"$kushner" filter --model-file "$examples/cubic_oscillator.toml" "${exact[@]}" --out "$work/exact-file"
echo "cubic oscillator, built-in vs file (EXACT, the grid filter):"
compare_summaries "$work/exact-builtin/summary.json" "$work/exact-file/summary.json" ||
  fail "the cubic-oscillator file does not give the built-in's grid filter"
# The comparison can fail: a drift coefficient changed by 1e-6 is far outside the tolerance.
sed 's/0\.125, 0\.0\]/0.125001, 0.0]/' "$examples/cubic_oscillator.toml" >"$work/perturbed.toml"
grep -q 0.125001 "$work/perturbed.toml" || fail "could not perturb the cubic-oscillator file"
"$kushner" compare --model-file "$work/perturbed.toml" "${common[@]}" --out "$work/cubic-perturbed"
if compare_summaries "$work/cubic-builtin/summary.json" "$work/cubic-perturbed/summary.json" QLF=1e-10 MIXED=1e-10 \
  >/dev/null 2>&1; then
  fail "a perturbed coefficient went unnoticed"
fi
echo "ok: a coefficient changed by 1e-6 shows"

# 1b. Linear model, dim 2: every filter (KB included: the file's drift is linear) and PF.
common=(--members 32 --particles 256 --T 1 --dt 1e-2 --seed 9 --output-points 5 --quiet)
"$kushner" filter --model linear "${common[@]}" --out "$work/linear-builtin"
"$kushner" filter --model-file "$examples/linear2.toml" "${common[@]}" --out "$work/linear-file"
echo "linear (dim 2), built-in vs file (filter, every filter and PF):"
compare_summaries "$work/linear-builtin/summary.json" "$work/linear-file/summary.json" ||
  fail "the linear file does not give the built-in's numbers"

# 1c. Cubic sensor: a polynomial observation (h = x^3). Every filter both run (the file refuses KB, POLY3, POLY4,
# BILIN and MIXED, whose equations need a linear h, as the built-in refuses them for its drift), PF and EXACT.
# Bit for bit but QLF, whose E_N[x^3] the built-in writes as m^3 + 3 m p and the file sums per Isserlis pairing.
cs=(--members 16 --particles 512 --T 0.5 --dt 1e-2 --seed 3 --output-points 5 --quiet --no-plots)
"$kushner" compare --model cubic-sensor "${cs[@]}" --out "$work/cs-builtin"
"$kushner" compare --model-file "$examples/cubic_sensor.toml" "${cs[@]}" --out "$work/cs-file"
echo "cubic sensor, built-in vs file (compare, every filter and PF):"
compare_summaries "$work/cs-builtin/summary.json" "$work/cs-file/summary.json" QLF=1e-10 ||
  fail "the cubic-sensor file does not give the built-in's numbers"
"$kushner" filter --model cubic-sensor --filters EKF,EXACT --members 3 --T 0.1 --dt 1e-2 --seed 5 --quiet \
  --output-points 2 --out "$work/cs-exact-builtin"
"$kushner" filter --model-file "$examples/cubic_sensor.toml" --filters EKF,EXACT --members 3 --T 0.1 --dt 1e-2 \
  --seed 5 --quiet --output-points 2 --out "$work/cs-exact-file"
compare_summaries "$work/cs-exact-builtin/summary.json" "$work/cs-exact-file/summary.json" ||
  fail "the cubic-sensor file does not give the built-in's grid filter"
python3 - "$work/cs-file/summary.json" <<'PY' || fail "cubic-sensor file: filters or summary"
import json, sys
s = json.load(open(sys.argv[1]))
assert not {"KB", "POLY3", "POLY4", "BILIN", "MIXED"} & set(s["filter_order"]), s["filter_order"]
h = s["model"]["polynomial"]["observation"]
assert h["terms"] == [{"component": 1, "powers": [3], "coefficient": 1.0}] and h["degree"] == 3, h
# EKF-DS and SOF-B use h'' = 6x: on a nonlinear observation they are other filters than EKF and SOF.
f = s["filters"]
assert f["EKF-DS"]["rmse_truth"] != f["EKF"]["rmse_truth"] and f["SOF-B"]["rmse_truth"] != f["SOF"]["rmse_truth"], f
PY
echo "ok: a polynomial observation runs as the built-in cubic sensor"

# 1d. Control: the linear and cubic-oscillator files carry the built-ins' input B = (0, 1); every controller the
# file model takes gives the built-in's cost.
ctl=(control --members 40 --particles 128 --T 0.5 --dt 1e-2 --seed 7 --quiet --no-plots
     --controllers NONE@state,LQR@state,LQR@EKF,LQR@PF,ASRE@state)
"$kushner" "${ctl[@]}" --model linear --out "$work/ctl-builtin"
"$kushner" "${ctl[@]}" --model-file "$examples/linear2.toml" --out "$work/ctl-file"
"$kushner" "${ctl[@]}" --model cubic-oscillator --out "$work/ctl-cubic-builtin"
"$kushner" "${ctl[@]}" --model-file "$examples/cubic_oscillator.toml" --out "$work/ctl-cubic-file"
python3 - "$work"/ctl-builtin/summary.json "$work"/ctl-file/summary.json "$work"/ctl-cubic-builtin/summary.json \
  "$work"/ctl-cubic-file/summary.json <<'PY' || fail "control: a file with [control] does not give the built-in's costs"
import json, sys
runs = [json.load(open(p)) for p in sys.argv[1:5]]
for builtin, file in (runs[0:2], runs[2:4]):
    assert builtin["controller_order"] == file["controller_order"], (builtin["controller_order"], file["controller_order"])
    for name in builtin["controller_order"]:
        a, b = builtin["controllers"][name]["J"], file["controllers"][name]["J"]
        assert abs(a - b) <= 1e-12 * abs(a), (name, a, b)
    print("  %s: J equal for %s" % (builtin["model"]["name"], ", ".join(builtin["controller_order"])))
PY
echo "ok: control on a model file with [control] gives the built-in's costs"

# 1e. simulate: the same truths.
sim=(--members 500 --T 1 --dt 1e-2 --seed 2 --output-points 4 --quiet)
"$kushner" simulate --model cubic-oscillator "${sim[@]}" --out "$work/sim-builtin"
"$kushner" simulate --model-file "$examples/cubic_oscillator.toml" "${sim[@]}" --out "$work/sim-file"
# To 1e-12 relative, not bit for bit: the file's diffusion has two noise columns (its second zero), so its truth
# step draws cos and sin of each Box-Muller angle where the built-in draws cos only, and GCC vectorizes the two
# member loops differently (libmvec's and libm's cos differ in the last bit).
compare_timeseries "$work/sim-builtin/timeseries.csv" "$work/sim-file/timeseries.csv" ||
  fail "simulate: the cubic-oscillator file gives other truths"
echo "ok: simulate gives the built-in's truths"

# 1f. Discrete time (time = "discrete"): the linear-discrete file gives the built-in's numbers bit for bit (KF, KF-INF,
# EKF-D, the particle filter and the grid Bayes filter (EXACT), the Riccati controller) and its truths to 1e-12.
# The Duffing file (nonlinear transition, one observed coordinate) runs the filters its coefficients allow.
dd=(--filters KF,KF-INF,EKF-D,PF,EXACT --members 16 --particles 512 --T 10 --seed 4 --output-points 5 --quiet --no-plots)
"$kushner" compare --model linear-discrete "${dd[@]}" --out "$work/ld-builtin"
"$kushner" compare --model-file "$examples/linear_discrete.toml" "${dd[@]}" --out "$work/ld-file"
echo "linear-discrete, built-in vs file (compare, KF, KF-INF, EKF-D, PF, EXACT):"
compare_summaries "$work/ld-builtin/summary.json" "$work/ld-file/summary.json" ||
  fail "the linear-discrete file does not give the built-in's numbers"
"$kushner" simulate --model linear-discrete --members 200 --T 20 --seed 2 --output-points 5 --quiet --out "$work/ld-sim-builtin"
"$kushner" simulate --model-file "$examples/linear_discrete.toml" --members 200 --T 20 --seed 2 --output-points 5 --quiet \
  --out "$work/ld-sim-file"
# To 1e-12 (measured 3e-16): the two transitions' member loops vectorize differently, as above.
compare_timeseries "$work/ld-sim-builtin/timeseries.csv" "$work/ld-sim-file/timeseries.csv" ||
  fail "simulate: the linear-discrete file gives other truths"
dctl=(control --members 40 --particles 128 --T 20 --seed 7 --quiet --no-plots --controllers NONE@state,LQR@state,LQR@KF,LQR@PF)
"$kushner" "${dctl[@]}" --model linear-discrete --out "$work/ld-ctl-builtin"
"$kushner" "${dctl[@]}" --model-file "$examples/linear_discrete.toml" --out "$work/ld-ctl-file"
"$kushner" filter --model-file "$examples/duffing_discrete.toml" --filters all,EXACT --members 40 --particles 1024 --T 30 \
  --seed 3 --quiet --out "$work/duffing"
"$kushner" filter --model-file "$examples/duffing_discrete.toml" --filters PF,EXACT --members 40 --particles 16384 --T 30 \
  --seed 3 --quiet --out "$work/duffing-16k"
python3 - "$work"/ld-ctl-builtin/summary.json "$work"/ld-ctl-file/summary.json "$work/duffing/summary.json" \
  "$work/ld-file/summary.json" "$work/duffing-16k/summary.json" <<'PY' || fail "discrete model files: control, Duffing run or summary"
import json, math, sys
builtin, file, duffing, ld, duffing16 = (json.load(open(p)) for p in sys.argv[1:6])
assert builtin["controller_order"] == file["controller_order"], (builtin["controller_order"], file["controller_order"])
for name in builtin["controller_order"]:
    assert builtin["controllers"][name]["J"] == file["controllers"][name]["J"], name
m = ld["model"]
assert m["name"] == "polynomial-discrete" and m["polynomial"]["time"] == "discrete", m
assert m["polynomial"]["transition"]["a1"] == [[0.9, 0.2], [-0.2, 0.9]], m["polynomial"]
assert m["polynomial"]["process_noise"]["G"] == [[0.5, 0.0], [0.0, 0.5]], m["polynomial"]
# Duffing: KF and KF-INF need a linear transition; EKF-D and KF-NOM (linearized along the noise-free path) run.
assert duffing["filter_order"] == ["EKF-D", "KF-NOM", "PF", "EXACT"], duffing["filter_order"]
f = duffing["filters"]
for name, v in f.items():
    assert math.isfinite(v["rmse_truth"]) and v["diverged"] == 0, (name, v)
# The grid Bayes filter is the particle filter's limit: their distance falls like N^-1/2 (16x the particles: /4;
# measured 0.080 -> 0.0166, and 0.0058 at 131072), where EKF-D's stays (0.17, 0.15).
near, nearer = f["EXACT"]["rmse_ref"], duffing16["filters"]["EXACT"]["rmse_ref"]
assert near / nearer > 2.5, (near, nearer)
assert f["EXACT"]["rmse_truth"] <= f["EKF-D"]["rmse_truth"] and f["EKF-D"]["rmse_ref"] > 5 * nearer, f
print("  Duffing rmse_truth:", {n: round(v["rmse_truth"], 4) for n, v in f.items()},
      "EXACT rmse_ref %.4f (1024 particles), %.4f (16384)" % (near, nearer))
PY
echo "ok: discrete-time model files (linear-discrete bit for bit, its control and truths; the Duffing file)"

# 2. What summary.json records; --set on the initial law.
python3 - "$work/cubic-file/summary.json" "$examples/cubic_oscillator.toml" <<'PY' || fail "summary.json model entry"
import json, sys
m = json.load(open(sys.argv[1]))["model"]
assert m["name"] == "polynomial" and m["file"] == sys.argv[2] and m["label"] == "cubic oscillator (file)", m
p = m["polynomial"]
assert p["state_dim"] == 2 and p["obs_dim"] == 2 and p["noise_dim"] == 1, p
assert p["drift"]["a1"] == [[0.0, 1.0], [-1.0, -1.0]] and p["drift"]["degree"] == 3, p["drift"]
assert p["drift"]["terms"] == [{"component": 2, "powers": [3, 0], "coefficient": 0.125}], p["drift"]["terms"]
assert p["diffusion"]["b"] == [[0.0], [0.5]], p["diffusion"]
assert m["parameters"]["x0_mean"] == [1.5, 1.0], m["parameters"]
PY
"$kushner" filter --model-file "$examples/van_der_pol.toml" --set x0_mean=2,0 --filters EKF,QLF,MIXED,PF \
  --members 8 --particles 128 --T 0.2 --dt 1e-2 --quiet --out "$work/vdp"
python3 - "$work/vdp/summary.json" <<'PY' || fail "van der Pol run"
import json, math, sys
s = json.load(open(sys.argv[1]))
assert s["model"]["parameters"]["x0_mean"] == [2.0, 0.0], s["model"]
assert s["model"]["polynomial"]["obs_dim"] == 1, s["model"]
assert s["filter_order"] == ["EKF", "QLF", "MIXED", "PF"], s["filter_order"]
for f in s["filters"].values():
    assert math.isfinite(f["rmse_truth"]), f
PY
echo "ok: summary.json records the file and its coefficients; --set x0_mean applies"

# 1-D and 3-D files run too: the double well with the particle and grid filters, Lorenz 63 with every filter
# its bilinear drift allows. On a quadratic drift the second-order filters, QLF and BILIN are one filter (the
# Hessian correction and the Gaussian moments are exact): equal to rounding.
"$kushner" filter --model-file "$examples/double_well.toml" --filters EKF,QLF,POLY3,POLY4,PF,EXACT --members 8 \
  --particles 512 --T 0.3 --dt 1e-2 --quiet --out "$work/dw"
"$kushner" filter --model-file "$examples/lorenz63.toml" --members 4 --particles 128 --T 0.02 --dt 1e-3 --quiet \
  --out "$work/lorenz"
python3 - "$work/dw/summary.json" "$work/lorenz/summary.json" <<'PY' || fail "double well or Lorenz 63 run"
import json, math, sys
dw, lz = (json.load(open(p)) for p in sys.argv[1:3])
assert dw["filter_order"] == ["EKF", "QLF", "POLY3", "POLY4", "PF", "EXACT"], dw["filter_order"]
assert dw["filters"]["EXACT"]["estimator"]["kind"] == "grid", dw["filters"]["EXACT"]
allowed = ["EKF", "EKF-DS", "SOF", "SOF-B", "QLF", "BILIN", "MIXED", "ASRE", "KBL"]  # its bilinear drift allows these
assert [n for n in lz["filter_order"] if n in allowed] == allowed and lz["filter_order"][-1] == "PF", lz["filter_order"]
assert not {"KB", "POLY3", "POLY4"} & set(lz["filter_order"]), lz["filter_order"]
for s in (dw, lz):
    for name, f in s["filters"].items():
        assert math.isfinite(f["rmse_truth"]) and f["diverged"] == 0, (name, f)
f = lz["filters"]
for name in ("SOF", "SOF-B", "QLF"):
    assert abs(f[name]["rmse_truth"] - f["BILIN"]["rmse_truth"]) <= 1e-9 * f["BILIN"]["rmse_truth"], (name, f[name], f["BILIN"])
PY
echo "ok: 1-D (double well, PF and grid filter) and 3-D (Lorenz 63) files run"

# Same seed, same bits on every host backend and thread count (as for the built-in models).
if grep -qw openmp <<<"$backends" && grep -qw serial <<<"$backends"; then
  det=(filter --model-file "$examples/van_der_pol.toml" --filters all --members 40 --particles 256 --T 0.2 --dt 1e-2
       --output-points 4 --quiet --out out)
  (cd "$work" && KUSHNER_BACKEND=serial "$kushner" "${det[@]}" && mv out det-serial)
  (cd "$work" && KUSHNER_BACKEND=openmp OMP_NUM_THREADS=2 "$kushner" "${det[@]}" && mv out det-omp2)
  cmp "$work/det-serial/timeseries.csv" "$work/det-omp2/timeseries.csv" ||
    fail "van der Pol file: timeseries.csv differs between serial and 2 OpenMP threads"
  echo "ok: a model file gives the same bits on serial and 2 OpenMP threads"
fi

# 3. Bad input.
expect_refused() {  # expect_refused "message" args...: exactly that line, exit 2, nothing in --out
  local expected=$1; shift
  run_kushner "$work/r" "$@"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  [ "$(cat "$work/r.err")" = "kushner: error: $expected" ] ||
    fail "message for: $*: $(cat "$work/r.err") (want: kushner: error: $expected)"
  [ ! -s "$work/r.out" ] || fail "stdout not empty for: $*"
  echo "ok: $expected"
}
bad() {  # bad NAME: writes $work/NAME.toml from stdin
  cat >"$work/$1.toml"
}
tail_ok='[diffusion]
b = [[0.5, 0.0], [0.0, 0.5]]
[observation]
C = [[1.0, 0.0], [0.0, 1.0]]
R = [[0.5, 0.0], [0.0, 0.5]]
[initial]
x0_mean = [1.0, 1.0]
x0_cov = [[0.1, 0.0], [0.0, 0.1]]'
printf 'state_dim = 2\n[drift\na1 = [[1.0]]\n' | bad malformed
printf '%s\n' "$tail_ok" | bad no_dim
printf 'state_dim = 2\n%s\n' "$(sed '/^R = /d' <<<"$tail_ok")" | bad no_R
printf 'state_dim = 2\n[drift]\na2 = [[[0.0, 1.0], [0.0, 0.0]], [[1.0, 0.0]]]\n%s\n' "$tail_ok" | bad shape
printf 'state_dim = 2\n[drift]\na1 = [[0.0, 1.0], [-1.0, "x"]]\n%s\n' "$tail_ok" | bad type
printf 'state_dim = 2\n[drift]\nA = [[0.0, 1.0], [-1.0, 0.0]]\n%s\n' "$tail_ok" | bad unknown
sed 's/^x0_cov = .*/x0_cov = [[0.1, 0.0], [0.0, -0.1]]/' <<<"state_dim = 2
$tail_ok" | bad indefinite

out="$work/refused"
expect_refused "$work/malformed.toml: line 2, column 7: not TOML: Error while parsing table header: expected ']', saw '\\n'" \
  simulate --model-file "$work/malformed.toml" --out "$out"
expect_refused "$work/no_dim.toml: state_dim: missing (required: the state dimension, 1, 2 or 3)" \
  filter --model-file "$work/no_dim.toml" --out "$out"
expect_refused "$work/no_R.toml: observation.R: missing (required: a 2x2 array)" \
  compare --model-file "$work/no_R.toml" --out "$out"
expect_refused "$work/shape.toml: drift.a2: expected a 2x2x2 array, but drift.a2[1] has 1 entry" \
  filter --model-file "$work/shape.toml" --out "$out"
expect_refused "$work/type.toml: drift.a1: expected a 2x2 array, but drift.a1[1][1] is a string" \
  filter --model-file "$work/type.toml" --out "$out"
expect_refused "$work/unknown.toml: drift.A: unknown key (known here: a0, a1, a2, a3, a4, terms)" \
  filter --model-file "$work/unknown.toml" --out "$out"
expect_refused "$work/indefinite.toml: initial.x0_cov: not positive semidefinite (smallest eigenvalue -0.1)" \
  simulate --model-file "$work/indefinite.toml" --out "$out"
expect_refused "--model-file: cannot read '$work/nothing.toml'" filter --model-file "$work/nothing.toml" --out "$out"
expect_refused "--model-file: give either --model or --model-file, not both (the file defines the model)" \
  filter --model sine --model-file "$examples/linear2.toml" --out "$out"
expect_refused "filter POLY3 does not support model 'polynomial' (drift has cross terms (monomials of two or more variables), not componentwise powers)" \
  filter --model-file "$examples/van_der_pol.toml" --filters EKF,POLY3 --out "$out"
expect_refused "filter KB does not support model 'polynomial' (drift is not linear (the file has terms of degree 2 or more))" \
  compare --model-file "$examples/cubic_oscillator.toml" --filters KB --out "$out"
expect_refused "--model-file $examples/van_der_pol.toml: no control input (add a [control] table with B, the input's column, e.g. B = [0.0, 1.0])" \
  control --model-file "$examples/van_der_pol.toml" --out "$out"
expect_refused "filter MIXED does not support model 'polynomial' (observation is not linear (the file has terms of degree 2 or more))" \
  filter --model-file "$examples/cubic_sensor.toml" --filters EKF,MIXED --out "$out"
printf 'state_dim = 2\ntime = "sometimes"\n[drift]\n%s\n' "$tail_ok" | bad bad_time
printf 'state_dim = 2\ntime = "discrete"\n[drift]\n%s\n' "$tail_ok" | bad discrete_drift
printf 'state_dim = 2\n[transition]\na1 = [[1.0, 0.0], [0.0, 1.0]]\n%s\n' "$tail_ok" | bad continuous_transition
sed 's/^G = .*/G = [[0.5, 0.1],/' "$examples/linear_discrete.toml" >"$work/correlated.toml"
expect_refused "$work/bad_time.toml: time: expected \"continuous\" or \"discrete\"" \
  filter --model-file "$work/bad_time.toml" --out "$out"
expect_refused "$work/discrete_drift.toml: drift: a discrete-time model (time = \"discrete\") has [transition] and [process_noise], not [drift] and [diffusion]" \
  filter --model-file "$work/discrete_drift.toml" --out "$out"
expect_refused "$work/continuous_transition.toml: transition: a continuous-time model has [drift] and [diffusion]; [transition] and [process_noise] are a discrete one's (time = \"discrete\")" \
  filter --model-file "$work/continuous_transition.toml" --out "$out"
expect_refused "filter EXACT does not support model 'polynomial-discrete' (the discrete grid filter needs axis-aligned process noise (G G^T diagonal))" \
  filter --model-file "$work/correlated.toml" --filters KF,EXACT --out "$out"
expect_refused "filter KF does not support model 'polynomial-discrete' (transition is not linear (the file has terms of degree 2 or more))" \
  filter --model-file "$examples/duffing_discrete.toml" --filters KF --out "$out"
expect_refused "filter KF-NOM does not support model 'polynomial-discrete' (transition is linear (the nominal path changes nothing: use KF))" \
  filter --model-file "$examples/linear_discrete.toml" --filters KF-NOM --out "$out"
expect_refused "--dt: a discrete-time model steps k = 0, 1, ..., T; --dt must be 1 (got 0.01)" \
  filter --model-file "$examples/linear_discrete.toml" --dt 0.01 --out "$out"
expect_refused "--set q: a --model-file model takes x0_mean, x0_cov, prior_mean, prior_cov (the other coefficients are edited in $examples/cubic_oscillator.toml)" \
  filter --model-file "$examples/cubic_oscillator.toml" --set q=1 --out "$out"
[ ! -e "$out" ] || fail "a refused run created $out"

# Results already written survive refused runs into the same directory.
before=$(cd "$work/linear-file" && cat * | md5sum)
count=$(ls "$work/linear-file" | wc -l)
expect_refused "$work/shape.toml: drift.a2: expected a 2x2x2 array, but drift.a2[1] has 1 entry" \
  filter --model-file "$work/shape.toml" --out "$work/linear-file"
expect_refused "filter BILIN does not support model 'polynomial' (drift is not bilinear (degree above 2))" \
  filter --model-file "$examples/cubic_oscillator.toml" --filters BILIN --out "$work/linear-file"
[ "$before" = "$(cd "$work/linear-file" && cat * | md5sum)" ] || fail "a refused run changed results already written"
[ "$(ls "$work/linear-file" | wc -l)" -eq "$count" ] || fail "stray files in $work/linear-file"
echo "all model-file checks passed"
