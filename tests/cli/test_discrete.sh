#!/usr/bin/env bash
# Discrete-time models through the command line (issue 15): `filter`/`compare` run the discrete filters and
# references, time is the step index (dt = 1), and bad input gets one line and exit 2 with nothing written.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

expect_refused "--dt: a discrete-time model steps k = 0, 1, ..., T; --dt must be 1 (got 0.5)" \
  filter --model clark-linear --dt 0.5
expect_refused "--T: must be a whole number of --dt steps (T/dt = 10.5)" filter --model clark-linear --T 10.5
expect_refused "rho_w, rho_v: must be at least 0 (got -1, 0)" filter --model clark-linear --set rho_w=-1
expect_refused "bound_w, bound_v: must be positive (got 1, 0)" filter --model clark-linear --set bound_v=0
expect_refused "R: R R^T must be positive definite" filter --model linear-discrete --set 'R=1,0;0,0'
expect_refused "filter KF does not support model 'clark-quintic' (transition is not linear)" \
  filter --model clark-quintic --filters KF
expect_refused "filter KF-NOM does not support model 'clark-linear' (transition is linear (the nominal path changes nothing: use KF, MOM))" \
  filter --model clark-linear --filters KF-NOM
expect_refused "filter MOM does not support model 'linear-discrete' (state or observation is not scalar)" \
  filter --model linear-discrete --filters MOM
expect_refused "filter EKF does not support model 'clark-linear' (a continuous-time filter; the model is discrete-time)" \
  filter --model clark-linear --filters EKF
expect_refused "filter KF does not support model 'sine' (a discrete-time filter; the model is continuous-time)" \
  filter --model sine --filters KF
expect_refused "filter EXACT does not support model 'linear-discrete' (the discrete grid filter needs axis-aligned process noise (G G^T diagonal))" \
  filter --model linear-discrete --filters KF,EXACT --set 'G=0.5,0.1;0,0.5'
expect_refused "--mom-order: must be in 1 .. 14 (got 20)" filter --model clark-linear --filters MOM --mom-order 20

# A run: every discrete filter, the particle filter and the grid Bayes filter on clark-linear; steps of 1.
"$kushner" filter --model clark-linear --filters all,EXACT --members 300 --particles 512 --T 20 --seed 4 \
  --out "$work/run" --quiet
python3 - "$work/run" <<'PY' || fail "clark-linear run"
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
assert s["dt"] == 1 and s["steps"] == 20, (s["dt"], s["steps"])
order = s["filter_order"]
assert order == ["KF", "KF-INF", "EKF-D", "MOM", "MOM-MID", "MOM-LS", "MOM-LINE", "MOM-HYP", "MOM-SPEC", "PF", "EXACT"], order
f = s["filters"]
for name in order:
    assert f[name]["diverged"] == 0, (name, f[name])
# KF = KF-INF = EKF-D on a linear model; the Bayes filter (grid) and the particle filter below KF; MOM between.
assert abs(f["KF"]["rmse_truth"] - f["KF-INF"]["rmse_truth"]) < 1e-10 and f["KF"]["rmse_truth"] == f["EKF-D"]["rmse_truth"]
assert f["EXACT"]["rmse_truth"] < f["MOM"]["rmse_truth"] < f["KF"]["rmse_truth"], [f[n]["rmse_truth"] for n in ("EXACT", "MOM", "KF")]
assert abs(f["PF"]["rmse_truth"] - f["EXACT"]["rmse_truth"]) < 0.02, (f["PF"]["rmse_truth"], f["EXACT"]["rmse_truth"])
assert f["EXACT"]["rmse_ref"] < 0.05, f["EXACT"]["rmse_ref"]
assert f["MOM"]["order"] == 4 and s["reference"]["name"] == "PF"
print("clark-linear rmse_truth:", {n: round(f[n]["rmse_truth"], 4) for n in order})
PY
echo "ok: clark-linear filter run"

# The nonlinear plant: EKF-D, KF and MOM along the nominal path (KF, MOM refused: nonlinear), the grid and the
# particle filter; the Gaussian linear model with its grid Bayes filter (EXACT).
"$kushner" filter --model clark-quintic --filters EKF-D,KF-NOM,MOM-NOM,PF,EXACT --members 100 --particles 256 --T 10 --out "$work/quintic" --quiet
"$kushner" filter --model linear-discrete --filters all,EXACT --members 100 --particles 256 --T 10 --out "$work/gauss" --quiet
python3 - "$work/quintic" "$work/gauss" <<'PY' || fail "clark-quintic or linear-discrete run"
import json, sys
q = json.load(open(sys.argv[1] + "/summary.json"))
assert q["filter_order"] == ["EKF-D", "KF-NOM", "MOM-NOM", "PF", "EXACT"], q["filter_order"]
assert all(f["diverged"] == 0 for f in q["filters"].values()), q["filters"]
assert q["filters"]["KF-NOM"]["nominal"].startswith("noise-free uncontrolled"), q["filters"]["KF-NOM"]
g = json.load(open(sys.argv[2] + "/summary.json"))
assert g["filter_order"] == ["KF", "KF-INF", "EKF-D", "PF", "EXACT"], g["filter_order"]
# On the Gaussian linear model KF is the exact filter: its distance to the particle filter is the particle
# filter's own Monte Carlo error (its noise floor). The grid Bayes filter (EXACT) is KF to its grid's error.
gf = g["filters"]
assert gf["KF"]["rmse_ref"] < 1.5 * g["reference"]["noise_floor"], (gf["KF"], g["reference"])
assert gf["EXACT"]["estimator"]["kind"] == "grid" and gf["EXACT"]["diverged"] == 0, gf["EXACT"]
assert abs(gf["EXACT"]["rmse_truth"] - gf["KF"]["rmse_truth"]) < 1e-6 * gf["KF"]["rmse_truth"], (gf["EXACT"], gf["KF"])
assert abs(gf["EXACT"]["rmse_ref"] - gf["KF"]["rmse_ref"]) < 1e-6 * gf["KF"]["rmse_ref"], (gf["EXACT"], gf["KF"])
PY
echo "ok: clark-quintic and linear-discrete runs"

# kushner control: the Riccati controller with the state, KF, MOM and the particle filter, Clark's cost with the
# estimation-error weight D; the laws a discrete model cannot take and the reference solvers are refused.
expect_refused "--controllers: ASRE@state: law ASRE cannot control model 'clark-linear' (discrete time: the Riccati controllers (LQR, LQR-NOM) and NONE only)" \
  control --model clark-linear --controllers ASRE@state
expect_refused "--controllers: LQR-NOM@state: law LQR-NOM cannot control model 'linear' (Clark's perturbation loop is for discrete-time plants)" \
  control --model linear --controllers LQR-NOM@state
expect_refused "--reference hjb: no reference solver for discrete-time models (use none)" \
  control --model clark-linear --controllers LQR@state --reference hjb
expect_refused "--cost D: not positive semidefinite (smallest eigenvalue -1)" control --model clark-linear --controllers LQR@KF --cost D=-1
"$kushner" control --model clark-linear --controllers NONE@state,LQR@state,LQR@KF,LQR@MOM,LQR@PF --cost D=5 \
  --members 300 --particles 256 --T 30 --seed 2 --out "$work/control" --quiet --no-plots
python3 - "$work/control" <<'PY' || fail "clark-linear control run"
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
c = s["controllers"]
assert s["dt"] == 1 and s["steps"] == 30 and "reference" not in s and "sum_{k<N}" in s["cost"]["form"]
assert c["LQR@state"]["J"] < c["NONE@state"]["J"], c
# D = 5 weighs the estimation error: the better estimators (MOM, PF) cost less than KF.
assert c["LQR@MOM"]["estimation_error"] < c["LQR@KF"]["estimation_error"], c
assert c["LQR@MOM"]["J"] < c["LQR@KF"]["J"] and c["LQR@PF"]["J"] < c["LQR@KF"]["J"], c
assert c["LQR@state"]["estimation_error"] == 0
assert 0.2 < c["LQR@KF"]["estimation_error"] < 0.3, c["LQR@KF"]["estimation_error"]  # KF's steady 0.239
print({k: (round(v["J"], 3), round(v["estimation_error"], 4)) for k, v in c.items()})
PY
echo "ok: clark-linear control"

# simulate takes the same time rule.
"$kushner" simulate --model clark-linear --members 50 --T 5 --out "$work/sim" --quiet
python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); assert s["steps"] == 5 and s["dt"] == 1' "$work/sim/summary.json" \
  || fail "simulate on a discrete-time model"
echo "ok: simulate"
