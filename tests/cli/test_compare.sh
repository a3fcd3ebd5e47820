#!/usr/bin/env bash
# `kushner compare` and the particle/exact references on the command line: every artefact is written, each
# filter gets rmse_ref against the particle filter, EXACT is scored against it too, and bad input is refused
# with one line, exit 2 and nothing written.
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
small=(--members 12 --particles 256 --T 1 --dt 1e-2 --output-points 20 --quiet)

run_kushner "$work/c" compare "${small[@]}" --out "$work/c1"
[ "$rc" -eq 0 ] || fail "compare failed: $(cat "$work/c.err")"
artefacts=(summary.json timeseries.csv trajectories.csv density.csv report.md)
figures=yes
can_draw_figures || figures=no  # e.g. the GPU machine
[ $figures = no ] || artefacts+=(estimates.png estimates.svg errors.png rmse_ref.png density.png density.svg)
for f in "${artefacts[@]}"; do
  [ -s "$work/c1/$f" ] || fail "compare did not write $f ($(grep -o '"plots_error": "[^"]*"' "$work/c1/summary.json"))"
done
if [ $figures = no ]; then  # report.md still comes, with its tables and why there are no figures
  grep -q "Not drawn: matplotlib is not installed" "$work/c1/report.md" || fail "report.md does not say why no figures"
  echo "note: no matplotlib for $plot_python, figures not checked"
fi
ls "$work/c1" | grep -q '\.tmp' && fail "temporary files left behind"
python3 - "$work/c1" <<'PY' || fail "compare summary.json or CSV files incomplete"
import csv, json, math, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
assert s["model"]["name"] == "sine", s["model"]
assert s["reference"]["kind"] == "particle filter" and s["reference"]["particles"] == 256, s["reference"]
assert s["reference"]["mean_ess"] > 0 and s["reference"]["noise_floor"] > 0, s["reference"]
filters = s["filters"]
assert "PF" in filters and "rmse_ref" not in filters["PF"], "the reference has no rmse_ref of its own"
for name in ("EKF", "SOF", "QLF", "KBL", "ASRE"):
    f = filters[name]
    assert math.isfinite(f["rmse_ref"]) and f["rmse_ref"] > 0 and math.isfinite(f["rmse_ref_se"]), (name, f)
    assert math.isfinite(f["rmse_truth"]) and math.isfinite(f["nees"]), (name, f)
# KBL (linearized at 0) is far from the conditional mean on the sine model; QLF is close to it.
assert filters["KBL"]["rmse_ref"] > filters["QLF"]["rmse_ref"], filters
rows = list(csv.DictReader(l for l in open(os.path.join(d, "trajectories.csv")) if not l.startswith("#")))
series = {r["series"] for r in rows}
assert {"truth", "PF", "QLF", "EKF"} <= series, series
assert {r["member"] for r in rows} == {"0", "1", "2"}, {r["member"] for r in rows}
for r in rows:
    assert float(r["lower"]) <= float(r["estimate"]) <= float(r["upper"]), r
dens = list(csv.DictReader(l for l in open(os.path.join(d, "density.csv")) if not l.startswith("#")))
assert len({r["t"] for r in dens if r["snapshot"] == "time"}) == 3, {r["t"] for r in dens}
bimodal = s["density"]["most_bimodal"]
shown = {r["member"] for r in dens if r["snapshot"] == "most_bimodal"}
assert shown == ({str(bimodal["member"])} if bimodal["member"] >= 0 else set()), (shown, bimodal)
assert -1 <= bimodal["member"] < bimodal["scanned_members"] == 12 and 0 <= bimodal["score"] <= 1, bimodal
pf = [r for r in dens if r["series"] == "PF" and r["t"] == dens[0]["t"] and r["snapshot"] == "time"]
width = float(pf[1]["x"]) - float(pf[0]["x"])
assert abs(sum(float(r["density"]) for r in pf) * width - 1) < 0.01, "PF histogram does not integrate to ~1"
assert "rmse_ref" in open(os.path.join(d, "report.md")).read()
# The banks' bytes: the sine model (n = 1) with systematic resampling keeps per particle its state and scratch
# copy (2 x 8 B), its log-weight (8 B) and ancestor (4 B); where step pairs are fused (a GPU's default), also the
# second bank's state and log-weight (16 B).
mem = s["memory"]
fused = s["reference"]["step_pairs"] == "fused"
assert mem["particle_bytes_per_particle"] == (44 if fused else 28), (mem, s["reference"]["step_pairs"])
assert mem["total_bytes"] > 12 * 256 * 28 and mem["bank_bytes_per_member"] > 0, mem
assert "- memory: " in open(os.path.join(d, "report.md")).read()
PY
echo "ok: compare artefacts"

# PF and EXACT (the grid filter on the sine model) side by side: EXACT is scored against the particle mean.
run_kushner "$work/e" filter --model sine --filters QLF,PF,EXACT --members 8 --particles 2048 --T 0.5 --dt 1e-2 \
  --quiet --out "$work/e1"
[ "$rc" -eq 0 ] || fail "filter with PF,EXACT failed: $(cat "$work/e.err")"
python3 - "$work/e1/summary.json" <<'PY' || fail "EXACT not scored against PF"
import json, sys
s = json.load(open(sys.argv[1]))
f = s["filters"]
assert s["filter_order"] == ["QLF", "PF", "EXACT"], s["filter_order"]
assert f["EXACT"]["estimator"]["kind"] == "grid", f["EXACT"]
# The grid filter and the particle filter approximate the same conditional mean: their distance is the
# particle filter's own Monte Carlo error (a few hundredths at 2048 particles), far below the state's spread.
assert f["EXACT"]["rmse_ref"] < 0.05, f["EXACT"]
assert abs(f["EXACT"]["rmse_truth"] - f["PF"]["rmse_truth"]) < 0.05, (f["EXACT"], f["PF"])
assert f["PF"]["estimator"]["precision"] == "fp64", f["PF"]
PY
# The coarser precisions, each against the next finer one's run (mixed against fp64's e1, fp32 against mixed's):
# recorded, and as close to the grid filter as fp64's particle filter. mixed draws the same Philox normals in fp32:
# the two particle filters' errors agree far below their noise floor (1e-3 against about 0.02), but not to the bit.
# fp32 also stores the particles and log-weights in float and takes its odd steps' normals from other words of the
# blocks (two steps from one block): its error differs from mixed's by Monte Carlo error, within the noise floor.
finer=e1
for precision in mixed fp32; do
  run_kushner "$work/m" filter --model sine --filters QLF,PF,EXACT --members 8 --particles 2048 --T 0.5 --dt 1e-2 \
    --precision $precision --quiet --out "$work/$precision"
  [ "$rc" -eq 0 ] || fail "filter with --precision $precision failed: $(cat "$work/m.err")"
  python3 - "$work/$precision/summary.json" "$work/$finer/summary.json" $precision <<'PY' || fail "$precision PF"
import json, sys
coarse, fine = (json.load(open(p))["filters"] for p in sys.argv[1:3])
assert coarse["PF"]["estimator"]["precision"] == sys.argv[3], coarse["PF"]
assert coarse["EXACT"]["rmse_ref"] < 0.05, coarse["EXACT"]
tolerance = coarse["PF"]["estimator"]["noise_floor"] if sys.argv[3] == "fp32" else 1e-3
assert abs(coarse["PF"]["rmse_truth"] - fine["PF"]["rmse_truth"]) < tolerance, (coarse["PF"], fine["PF"])
assert coarse["PF"]["rmse_truth"] != fine["PF"]["rmse_truth"], "the same bits as the finer precision"
PY
  echo "ok: --precision $precision"
  finer=$precision
done
# Step pairs (the bank scoring one step behind so that PF takes two steps per call): on the host the two steps
# run one after the other, so `always` must give every number of `never` bit for bit, with an odd step count (the
# last step single) and output times every 5 steps, some in the middle of a pair (a GPU's fused pass: the same
# numbers to 1e-10).
run_kushner "$work/p" filter --model sine --filters QLF,PF,EXACT --members 8 --particles 2048 --T 0.47 --dt 1e-2 \
  --output-points 9 --step-pairs always --quiet --out "$work/p1"
[ "$rc" -eq 0 ] || fail "filter with --step-pairs always failed: $(cat "$work/p.err")"
run_kushner "$work/p" filter --model sine --filters QLF,PF,EXACT --members 8 --particles 2048 --T 0.47 --dt 1e-2 \
  --output-points 9 --step-pairs never --quiet --out "$work/p2"
[ "$rc" -eq 0 ] || fail "filter with --step-pairs never failed: $(cat "$work/p.err")"
python3 - "$work/p1" "$work/p2" <<'PY' || fail "step pairs changed the numbers"
import json, os, re, sys
pairs, single = (json.load(open(os.path.join(d, "summary.json"))) for d in sys.argv[1:3])
fused = pairs["filters"]["PF"]["estimator"]["step_pairs"]
assert fused in ("unfused", "fused"), pairs["filters"]["PF"]
assert single["filters"]["PF"]["estimator"]["step_pairs"] == "off", single["filters"]["PF"]
tolerance = 0.0 if fused == "unfused" else 1e-10
def numbers(text):
    return [float(x) for x in re.findall(r"-?\d+\.?\d*(?:[eE][-+]?\d+)?|nan", text)]
def same(a, b):
    return len(a) == len(b) and all(x == y or (x != x and y != y) or abs(x - y) <= tolerance * abs(x)
                                    for x, y in zip(a, b))
for s in (pairs, single):
    s["filters"]["PF"]["estimator"].pop("step_pairs")
assert same(numbers(json.dumps(pairs["filters"], sort_keys=True)), numbers(json.dumps(single["filters"], sort_keys=True))), \
    (pairs["filters"], single["filters"])
rows = ["".join(l for l in open(os.path.join(d, "timeseries.csv")) if not l.startswith("#")) for d in sys.argv[1:3]]
assert rows[0].count("\n") > 9 and same(numbers(rows[0]), numbers(rows[1])), "timeseries.csv differs"
PY
echo "ok: --step-pairs always gives the numbers of single steps"
echo "ok: PF and EXACT"

expect_refused() {  # expect_refused "message fragment" args...: one line, exit 2, nothing written
  local expected=$1; shift
  run_kushner "$work/r" "$@" --out "$work/refused"
  [ "$rc" -eq 2 ] || fail "exit $rc (want 2) for: $*; stderr: $(cat "$work/r.err")"
  [ "$(wc -l <"$work/r.err")" -eq 1 ] || fail "stderr is not one line for: $*: $(cat "$work/r.err")"
  grep -qF -- "$expected" "$work/r.err" || fail "message lacks '$expected' for: $*: $(cat "$work/r.err")"
  [ ! -e "$work/refused" ] || fail "a refused run created its output directory: $*"
  echo "ok: $(cat "$work/r.err")"
}
expect_refused "--particles: must be at least 1 (got 0)" compare --particles 0
expect_refused "--resample: unknown scheme 'best'" compare --resample best
expect_refused "--ess-threshold: must be in [0, 1] (got 1.5)" compare --ess-threshold 1.5
expect_refused "--precision: unknown precision 'half' (known: fp64, mixed, fp32)" compare --precision half
expect_refused "--step-pairs: unknown value 'sometimes' (known: auto, always, never)" compare --step-pairs sometimes
expect_refused "--trajectory-members: member 99 is not in 0 .. 9" compare --members 10 --trajectory-members 99
expect_refused "--density-times: 20 is not in [0, T = 10]" compare --density-times 20
expect_refused "filter PF does not support model 'terpolymer' (state dimension above 4)" filter --model terpolymer --filters PF
expect_refused "filter EXACT (grid filter): prior_cov: not positive definite" filter --model car --filters EXACT
expect_refused "filter EXACT does not support model 'terpolymer'" filter --model terpolymer --filters EXACT
expect_refused "unknown filter 'PFF'" compare --filters QLF,PFF

# A refused run leaves an earlier run's results as they were.
before=$(md5sum "$work/c1/summary.json")
run_kushner "$work/r" compare --particles 0 --out "$work/c1"
[ "$rc" -eq 2 ] && [ "$(md5sum "$work/c1/summary.json")" = "$before" ] || fail "a refused run touched earlier results"
echo "ok: earlier results untouched"
