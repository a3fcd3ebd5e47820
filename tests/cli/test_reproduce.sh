#!/usr/bin/env bash
# `kushner reproduce`: basin-car-filter prints every paper value of both tables (both filters, both systems)
# next to ours and writes the artefacts; its deterministic numbers are pinned (tests/data) and recomputed by a
# second implementation (car_filter_reference.py); the other examples run at small sizes and fill their tables;
# bad input is refused with one line, exit 2, nothing written.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python=/usr/bin/python3
[ -x "$python" ] || python=python3

run_kushner "$work/car" reproduce basin-car-filter --out "$work/car" --quiet
[ "$rc" -eq 0 ] || fail "reproduce basin-car-filter failed: $(cat "$work/car.err")"
for f in summary.json reproduction.csv reproduction.md report.md; do
  [ -s "$work/car/$f" ] || fail "reproduce basin-car-filter did not write $f"
done
figures=(estimates.png estimates.svg errors.png errors.svg rmse_ref.png rmse_ref.svg)
can_draw_figures || { figures=(); echo "note: no matplotlib for $plot_python, figures not checked"; }
for run in taylor tan; do
  for f in summary.json timeseries.csv trajectories.csv report.md "${figures[@]}"; do
    [ -s "$work/car/$run/$f" ] || fail "reproduce basin-car-filter did not write $run/$f"
  done
done
find "$work/car" -name '*.tmp*' | grep -q . && fail "temporary files left behind"

# stdout: every row of the data file, with the paper's value and ours, for both filters and both systems.
"$python" - "$source_dir/drivers/reproduce/basin_car_filter.csv" "$work/car.out" "$work/car/reproduction.csv" <<'PY' \
  || fail "reproduce basin-car-filter: table incomplete"
import csv, math, re, sys
data = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#")))
out = open(sys.argv[2]).read().splitlines()
rows = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[3]) if not l.startswith("#"))}
for system in ("taylor", "tan"):
    for column in ("KB", "POLY3"):
        for q in ("phi", "delta", "m_phi", "m_delta"):
            assert any(d["key"] == f"{system}/{column}/{q}" and d["paper"] for d in data), (system, column, q)
for d in data:
    lines = [l for l in out if l.startswith(d["quantity"] + " ")]
    assert len(lines) == 1, f"stdout has {len(lines)} lines for {d['quantity']!r}"
    fields = lines[0][len(d["quantity"]):].split()
    paper = d["paper"] or "-"
    assert fields[0] == paper, f"{d['quantity']}: paper column {fields[0]!r}, data file {paper!r}"
    ours = float(rows[d["key"]]["ours"])
    assert math.isfinite(ours) and float(fields[1]) == float(f"{ours:.4g}"), (d["quantity"], fields, ours)
    verdict = " ".join(fields[2:])
    assert verdict == rows[d["key"]]["verdict"], (d["quantity"], verdict)
    assert verdict == ("no number in paper" if not d["paper"] else verdict), verdict
    assert verdict in ("reproduces", "does not reproduce", "no number in paper"), verdict
assert "## Reproduction: basin-car-filter" in open(sys.argv[3].replace("reproduction.csv", "report.md")).read()
PY
echo "ok: reproduce basin-car-filter prints all $(grep -c '^[a-z]*/' "$source_dir/drivers/reproduce/basin_car_filter.csv") rows"

# Regression: our deterministic numbers, pinned (tests/data/basin_car_filter_ours.csv, see its comment).
"$python" - "$here/../data/basin_car_filter_ours.csv" "$work/car/reproduction.csv" <<'PY' || fail "car numbers moved"
import csv, sys
pinned = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#"))}
rows = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[2]) if not l.startswith("#"))}
assert set(pinned) == set(rows), set(pinned) ^ set(rows)
for key, p in pinned.items():
    ours, want = float(rows[key]["ours"]), float(p["ours"])
    assert abs(ours - want) <= 1e-9 * max(1.0, abs(want)), f"{key}: {ours!r}, pinned {want!r}"
    assert rows[key]["verdict"] == p["verdict"], f"{key}: verdict {rows[key]['verdict']!r}, pinned {p['verdict']!r}"
print(f"ok: {len(pinned)} car numbers and verdicts as pinned")
PY
# A second implementation, at a coarser step to keep the test short (the same code paths as the default run).
run_kushner "$work/car-coarse" reproduce basin-car-filter --dt 1e-3 --out "$work/car-coarse" --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce basin-car-filter --dt 1e-3 failed: $(cat "$work/car-coarse.err")"
"$python" "$here/car_filter_reference.py" "$work/car-coarse/reproduction.csv" 1e-3 \
  || fail "car numbers differ from the Python reference"

# The other examples, small: every row filled, artefacts written.
small=(--members 6 --particles 64 --dt 0.01 --quiet --no-plots)
for example in sunahara-ex1 sunahara-ex2; do
  run_kushner "$work/$example" reproduce "$example" --out "$work/$example" "${small[@]}"
  [ "$rc" -eq 0 ] || fail "reproduce $example failed: $(cat "$work/$example.err")"
  for f in summary.json timeseries.csv trajectories.csv reproduction.csv reproduction.md; do
    [ -s "$work/$example/$f" ] || fail "reproduce $example did not write $f"
  done
  grep -q "no number in paper" "$work/$example.out" || fail "reproduce $example: no table on stdout"
done
"$python" - "$work/sunahara-ex2/summary.json" <<'PY' || fail "sunahara-ex2: the printed start does not escape"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["printed_x0"]["truths_escaped"] == s["printed_x0"]["members"] == 6, s["printed_x0"]
assert s["reproduce"]["example"] == "sunahara-ex2" and len(s["reproduce"]["rows"]) == 8, s["reproduce"]
PY
# sunahara-ex1 checks its own numbers: the table carries the run's summary.json values, and the run resolves
# the ranking it exists for: EKF's rmse_ref above QLF's by more than 4 combined standard errors (300 members,
# 512 particles: about 6.6 here; 100 members gave 6.5 and, after the truths' normals were laid out anew, 4.9: too
# close to the bound for a check to stand on). Power: with a perturbed reference (a 2-particle filter) the same
# check fails.
ex1_check='
import csv, json, math, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
rows = {r["key"]: r for r in csv.DictReader(l for l in open(d + "/reproduction.csv") if not l.startswith("#"))}
for key, r in rows.items():
    name, metric = key.split("/")
    f = s["filters"][name]
    assert float(r["ours"]) == f[metric] and float(r["standard_error"]) == f[metric + "_se"], (key, r, f)
ekf, qlf = s["filters"]["EKF"], s["filters"]["QLF"]
gap = ekf["rmse_ref"] - qlf["rmse_ref"]
se = math.hypot(ekf["rmse_ref_se"], qlf["rmse_ref_se"])
print(f"EKF - QLF rmse_ref {gap:.4g} = {gap / se:.3g} combined SE")
sys.exit(0 if gap > 4 * se else 3)
'
run_kushner "$work/ex1" reproduce sunahara-ex1 --out "$work/ex1" --members 300 --particles 512 --dt 0.01 --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce sunahara-ex1 failed: $(cat "$work/ex1.err")"
"$python" -c "$ex1_check" "$work/ex1" || fail "sunahara-ex1: its numbers do not rank EKF below QLF"
run_kushner "$work/ex1-off" reproduce sunahara-ex1 --out "$work/ex1-off" --members 300 --particles 2 --dt 0.01 --quiet \
  --no-plots
[ "$rc" -eq 0 ] || fail "reproduce sunahara-ex1 --particles 2 failed: $(cat "$work/ex1-off.err")"
set +e
"$python" -c "$ex1_check" "$work/ex1-off"
off_rc=$?
set -e
[ "$off_rc" -eq 3 ] || fail "sunahara-ex1: the ranking check passes with a 2-particle reference (exit $off_rc)"

# basin-terpolymer: the claim row's verdict and the numbers behind it, not the presence of the row.
run_kushner "$work/terp" reproduce basin-terpolymer --out "$work/terp" --dt 0.01 --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce basin-terpolymer failed: $(cat "$work/terp.err")"
"$python" - "$work/terp/reproduction.csv" <<'PY' || fail "basin-terpolymer: the claim does not hold in its own numbers"
import csv, sys
rows = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#"))}
bilin, mixed, kbl = (float(rows[k + "/rmse_truth"]["ours"]) for k in ("BILIN", "MIXED", "KBL"))
claim = rows["claim/bilinear_best"]["verdict"]
assert (claim == "reproduces") == (bilin < mixed and bilin < kbl), (claim, bilin, mixed, kbl)
assert claim == "reproduces" and kbl > 2 * bilin, (claim, bilin, mixed, kbl)
PY
echo "ok: sunahara-ex1 (its own numbers, and a perturbed reference fails), sunahara-ex2, basin-terpolymer"

# clark-table-2.1 and clark-table-4.3 (seed 003): the estimation-error column against the exact Bayes filter, the
# performance column from `kushner control`; MOM given the wrong measurement-noise shape.
run_kushner "$work/clark" reproduce clark-table-2.1 --out "$work/clark" --members 150 --particles 256 --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce clark-table-2.1 failed: $(cat "$work/clark.err")"
run_kushner "$work/clark43" reproduce clark-table-4.3 --out "$work/clark43" --members 200 --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce clark-table-4.3 failed: $(cat "$work/clark43.err")"
"$python" - "$work/clark" "$work/clark43" <<'PY' || fail "clark tables: numbers wrong"
import csv, json, re, sys
def table(d):
    return {r["key"]: r for r in csv.DictReader(l for l in open(d + "/reproduction.csv") if not l.startswith("#"))}
rows = table(sys.argv[1])
ours = lambda k: float(rows[k]["ours"])
# KF's steady-state error variance is 0.2394 for these noises: the printed 0.240 reproduces.
assert rows["KF/estimation_error"]["verdict"] == "reproduces", rows["KF/estimation_error"]
assert ours("EXACT/estimation_error") < ours("MOM/estimation_error") < ours("KF/estimation_error"), rows
assert float(rows["bayes_below_kf"]["ours"].split()[0]) > 5, rows["bayes_below_kf"]  # standard errors
# The performance column: J (no 1/2) over 1000 stages times the header's 6e-3; KF and MOM within 1% of each other.
for k in ("KF/performance", "MOM/performance"):
    assert rows[k]["verdict"] == "reproduces", rows[k]
assert abs(ours("KF/performance") - ours("MOM/performance")) < 0.01 * ours("KF/performance"), rows
s = json.load(open(sys.argv[1] + "/summary.json"))
assert set(s["runs"]) == {"estimation", "control"} and s["runs"]["control"]["steps"] == 1000
t43 = table(sys.argv[2])
low, high, se = (float(v) for v in re.findall(r"\d+\.\d+", t43["kf_constant"]["ours"])[:3])
assert high - low < 4 * se, t43["kf_constant"]  # KF sees only the variance, the same for every shape
mom = [float(t43["rho_%s/MOM" % r]["ours"]) for r in ("0", "0.1", "1", "2", "3", "7", "10")]
assert mom[0] > 2 * mom[3], mom  # the paper's fall from rho = 0 to 2 (.138 to .067)
print("ok: clark-table-2.1:", {k: rows[k]["ours"][:6] for k in rows if k.endswith("estimation_error")},
      "clark-table-4.3 MOM:", [round(m, 4) for m in mom])
PY

# clark-table-3.1 (seed 003 ch. III): the quintic plant in the perturbation loop, one control run per plant noise.
run_kushner "$work/clark31" reproduce clark-table-3.1 --out "$work/clark31" --members 120 --particles 1024 \
  --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce clark-table-3.1 failed: $(cat "$work/clark31.err")"
"$python" - "$work/clark31" <<'PY' || fail "clark-table-3.1: numbers wrong"
import csv, json, sys
rows = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[1] + "/reproduction.csv") if not l.startswith("#"))}
sigmas = ("0.05", "0.1", "0.2", "0.3", "0.545")
err = {(s, e): float(rows["sigma_%s/%s" % (s, e)]["ours"]) for s in sigmas for e in ("KF-NOM", "MOM-NOM", "PF")}
for e in ("KF-NOM", "MOM-NOM", "PF"):
    assert all(err[(a, e)] < err[(b, e)] for a, b in zip(sigmas, sigmas[1:])), (e, err)  # more noise, more error
assert err[("0.05", "MOM-NOM")] < err[("0.05", "KF-NOM")], err  # Clark's finding at low noise
assert err[("0.05", "PF")] < 1.1 * err[("0.05", "MOM-NOM")], err  # MOM-NOM is near optimal at low noise
s = json.load(open(sys.argv[1] + "/summary.json"))
assert sorted(s["runs"]) == ["sigma-" + x for x in sorted(sigmas)], sorted(s["runs"])
law = s["runs"]["sigma-0.1"]["controllers"]["LQR-NOM@KF-NOM"]
print("ok: clark-table-3.1:", {k: round(v, 4) for k, v in err.items() if k[1] != "PF"}, law.get("law", ""))
PY

# tarushkin-attitude (seed 004 §4): batch LS = recursive LS = information filter to rounding, and the estimates
# converge to the simulated coefficients as P predicts (50 members: NEES and RMS error within 4 standard errors).
run_kushner "$work/tarushkin" reproduce tarushkin-attitude --out "$work/tarushkin" --members 50 --quiet --no-plots
[ "$rc" -eq 0 ] || fail "reproduce tarushkin-attitude failed: $(cat "$work/tarushkin.err")"
for f in summary.json reproduction.csv reproduction.md convergence.csv coefficients.csv; do
  [ -s "$work/tarushkin/$f" ] || fail "reproduce tarushkin-attitude did not write $f"
done
"$python" - "$work/tarushkin" <<'PY' || fail "tarushkin-attitude: agreement or convergence numbers wrong"
import csv, json, math, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))["tarushkin"]
rows = {r["key"]: r for r in csv.DictReader(l for l in open(d + "/reproduction.csv") if not l.startswith("#"))}
assert rows["claim/filter_is_least_squares"]["verdict"] == "reproduces", rows["claim/filter_is_least_squares"]
assert s["compared_checkpoints"] >= 5, s
for key in ("agreement/rls", "agreement/info"):
    assert 0 <= float(rows[key]["ours"]) < 1e-10, (key, rows[key]["ours"])
assert abs(s["nees_T"] - 1) < 4 * s["nees_T_se"], (s["nees_T"], s["nees_T_se"])
assert abs(s["rms_error_T"] - s["predicted_rms_T"]) < 4 * s["rms_error_T_se"], s
assert -0.65 < s["slope"] < -0.35, s["slope"]
assert rows["observability/omega_orbit"]["ours"] == "12 of 15", rows["observability/omega_orbit"]
conv = list(csv.DictReader(l for l in open(d + "/convergence.csv") if not l.startswith("#")))
assert float(conv[-1]["rms_error"]) < 1e-3 * float(conv[0]["rms_error"]), (conv[0], conv[-1])
coef = list(csv.DictReader(l for l in open(d + "/coefficients.csv") if not l.startswith("#")))
assert len(coef) == 15 and all(abs(float(c["member0_batch"]) - float(c["member0_info"])) < 1e-12 for c in coef)
print(f"ok: tarushkin-attitude: agreement {float(rows['agreement/rls']['ours']):.2g}, "
      f"{float(rows['agreement/info']['ours']):.2g}; NEES {s['nees_T']:.3f} +- {s['nees_T_se']:.3f}; "
      f"RMS {s['rms_error_T']:.3g} vs predicted {s['predicted_rms_T']:.3g}; slope {s['slope']:.3f}")
PY

# Basin's regulators and controller (seed 002): files, every row of the data files on stdout with a verdict, and
# numbers that can fail: the printed linear q(0) to its printed digits, the direct optimum at most every law's J,
# the impossible printed J explained, the controller's loops equal to `kushner control`'s.
for example in basin-regulator-enotes basin-car-regulator basin-car-controller; do
  extra=()
  [ "$example" = basin-car-controller ] && extra=(--members 200)
  run_kushner "$work/$example" reproduce "$example" --out "$work/$example" --quiet --no-plots "${extra[@]}"
  [ "$rc" -eq 0 ] || fail "reproduce $example failed: $(cat "$work/$example.err")"
  for f in summary.json reproduction.csv reproduction.md; do
    [ -s "$work/$example/$f" ] || fail "reproduce $example did not write $f"
  done
  runs=(control)
  [ "$example" = basin-car-controller ] && runs=(control-sine control-brownian)
  for run in "${runs[@]}"; do
    for f in summary.json timeseries.csv; do
      [ -s "$work/$example/$run/$f" ] || fail "reproduce $example did not write $run/$f"
    done
  done
  csvname=${example//-/_}
  "$python" - "$source_dir/drivers/reproduce/$csvname.csv" "$work/$example.out" "$work/$example/reproduction.csv" \
    "$work/$example/summary.json" "$example" <<'PY' || fail "reproduce $example: table or numbers wrong"
import csv, json, math, sys
data = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#")))
out = open(sys.argv[2]).read().splitlines()
rows = {r["key"]: r for r in csv.DictReader(l for l in open(sys.argv[3]) if not l.startswith("#"))}
summary, example = json.load(open(sys.argv[4])), sys.argv[5]
assert [d["key"] for d in data] == list(rows), "rows differ from the data file"
for d in data:
    lines = [l for l in out if l.startswith(d["quantity"] + " ")]
    assert len(lines) == 1, f"stdout has {len(lines)} lines for {d['quantity']!r}"
    fields = lines[0][len(d["quantity"]):].split()
    assert fields[0] == (d["paper"] or "-"), (d["quantity"], fields)
    verdict = rows[d["key"]]["verdict"]
    assert verdict in ("reproduces", "does not reproduce", "no number in paper"), verdict
    assert (verdict == "no number in paper") == (not d["paper"]), (d["key"], verdict)
    assert verdict in lines[0], (d["quantity"], lines[0])
def ours(key):
    return float(rows[key]["ours"])
optimum = ours("optimum/J")
# The direct optimum is a floor: no law (printed or ours) has a smaller J (rounding of the optimizer allowed).
laws = [k for k in rows if k.endswith("/J") and not k.startswith("optimum") and rows[k]["ours"] != "none"]
assert laws, "no law rows"
for k in laws:
    assert ours(k) >= optimum - 1e-6 * abs(optimum), f"{k}: J {ours(k)} below the optimum {optimum}"
if example == "basin-regulator-enotes":
    # Our printed linear regulator (12): q(0) = (1.025, 0.87, 0.74) to the printed digits.
    for q, printed, half in (("q11", 1.025, 5e-4), ("q12", 0.87, 5e-3), ("q22", 0.74, 5e-3)):
        assert abs(ours(f"linear/printed/{q}") - printed) <= half, (q, ours(f"linear/printed/{q}"))
        assert rows[f"linear/printed/{q}"]["verdict"] == "reproduces"
    # The printed polynomial J = 0.065 is below the optimum 0.648: impossible, and said so.
    assert 0.64 < optimum < 0.66, optimum
    assert abs(ours("optimum/J_half") - optimum / 2) < 1e-12
    for reading in ("derived", "general", "eq23"):
        assert rows[f"poly/{reading}/J"]["verdict"] == "does not reproduce"
        assert rows[f"poly/{reading}/J"]["why"].startswith("impossible under the stated cost"), rows[f"poly/{reading}/J"]
    assert rows["poly/eq11/phi"]["ours"] == "none" and "escaped to infinity" in rows["poly/eq11/phi"]["why"]
    # Forwards from the printed q(0), (11) gives the printed phi(0.1) = 0.989, at a control energy far above J.
    assert rows["poly/eq11-forward/phi"]["verdict"] == "reproduces", rows["poly/eq11-forward/phi"]
    assert ours("poly/eq11-forward/J") > 10 and "impossible" in rows["poly/eq11-forward/J"]["why"]
if example == "basin-car-regulator":
    assert not any(rows[k]["why"] for k in rows if k.endswith("/J")), "T = 0.3: no printed J is impossible"
    assert ours("none/J") > optimum
if example == "basin-car-controller":
    # Basin's printed linear controller on KBL with sin t noises reproduces the paper's phi(0.3) = 0.0545.
    assert rows["sine/linear/printed/phi"]["verdict"] == "reproduces", rows["sine/linear/printed/phi"]
    assert abs(ours("sine/linear/printed/phi") - 0.0545) < 0.002
    assert float(rows["brownian/linear/LINCTL/J"]["standard_error"]) > 0
    # The table's own loops equal `kushner control`'s runs (same closed-loop code, seed, members).
    for noise in ("sine", "brownian"):
        ctl = summary["runs"]["control-" + noise]["controllers"]
        assert abs(ctl["LINCTL"]["J"] - ours(f"{noise}/linear/LINCTL/J")) <= 1e-9 * ours(f"{noise}/linear/LINCTL/J")
        assert abs(ctl["POLYCTL"]["J"] - ours(f"{noise}/poly/POLYCTL/J")) <= 1e-9 * ours(f"{noise}/poly/POLYCTL/J")
        assert abs(summary["runs"]["control-" + noise]["reference"]["J"] - optimum) <= 1e-9 * optimum
else:
    ctl = summary["runs"]["control"]
    assert abs(ctl["reference"]["J"] - optimum) <= 1e-9 * optimum
    assert abs(ctl["controllers"]["POLYREG"]["J"] - ours("poly/derived/J")) <= 1e-12 * optimum
    for name, c in ctl["controllers"].items():
        assert c["J"] >= optimum - 1e-6 * optimum, (name, c["J"], optimum)
print(f"ok: {example}: {len(rows)} rows, optimum J* = {optimum:.6g}")
PY
done

expect_refused() {  # expect_refused "message fragment" args...: one line, exit 2, nothing written
  local expected=$1; shift
  run_kushner "$work/r" "$@"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  grep -qF -- "$expected" "$work/r.err" || fail "message lacks '$expected' for: $*: $(cat "$work/r.err")"
  [ ! -s "$work/r.out" ] || fail "stdout not empty for: $*"
  [ ! -e "$work/refused" ] || fail "a refused run created its output directory: $*"
  echo "ok: $(cat "$work/r.err")"
}
expect_refused "reproduce: unknown example 'basin-car' (known: basin-car-filter, basin-terpolymer, basin-car-regulator, basin-regulator-enotes, basin-car-controller, sunahara-ex1, sunahara-ex2, clark-table-2.1, clark-table-3.1, clark-table-4.3, tarushkin-attitude)" \
  reproduce basin-car --out "$work/refused"
expect_refused "--out is required" reproduce basin-car-filter
expect_refused "--members: basin-car-filter is deterministic" reproduce basin-car-filter --members 10 --out "$work/refused"
expect_refused "--seed: basin-car-regulator is deterministic" reproduce basin-car-regulator --seed 3 --out "$work/refused"
expect_refused "--particles: basin-car-controller runs no particle filter" reproduce basin-car-controller --particles 64 --out "$work/refused"
expect_refused "--seed: basin-terpolymer is deterministic" reproduce basin-terpolymer --seed 3 --out "$work/refused"
expect_refused "--dt: the horizon of basin-car-filter, T = 20, must be a whole number of steps" reproduce basin-car-filter --dt 0.3 --out "$work/refused"
expect_refused "--dt: must be positive (got -0.1)" reproduce sunahara-ex1 --dt -0.1 --out "$work/refused"
expect_refused "--particles: must be at least 1 (got -4)" reproduce sunahara-ex1 --particles -4 --out "$work/refused"
expect_refused "--members: must be in 1 .." reproduce sunahara-ex2 --members -1 --out "$work/refused"
expect_refused "--members: must be in 1 .. 2147483647 (got 0)" reproduce sunahara-ex1 --members 0 --out "$work/refused"
expect_refused "--seed: must be in 0 .. 4294967295 (got -1)" reproduce sunahara-ex1 --seed -1 --out "$work/refused"
