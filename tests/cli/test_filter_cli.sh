#!/usr/bin/env bash
# `kushner filter` and `kushner filters`: what a run writes, and the refusals (exit 2, one line on stderr, no
# output directory created).
set -euo pipefail
kushner=$1
source "$(dirname "$0")/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

expect_refused "filter POLY3 does not support model 'car' (drift is not polynomial)" filter --model car --filters POLY3
expect_refused "filter KB does not support model 'sine' (model is not linear)" filter --model sine --filters EKF,KB
expect_refused "filter QLF does not support model 'car' (the drift has no Gaussian expectation)" filter --model car --filters QLF
expect_refused "filter BILIN does not support model 'cubic-oscillator' (drift is not bilinear)" \
  filter --model cubic-oscillator --filters BILIN
# The known names come from the filter list itself (`kushner filters --json`), so a new filter needs no edit here.
known=$("$kushner" filters --json | python3 -c 'import json, sys; print(", ".join(f["name"] for f in json.load(sys.stdin)))')
expect_refused "--filters: unknown filter 'NOPE' (known: $known, PF, EXACT, or all)" filter --model sine --filters EKF,NOPE
expect_refused "--filters: empty name in 'EKF,,SOF'" filter --model sine --filters EKF,,SOF
expect_refused "--qlf-expectations: model 'benes' has no closed-form Gaussian expectations (use cubature)" \
  filter --model benes --filters QLF --qlf-expectations closed
expect_refused "--qlf-expectations: cubature is limited to state_dim <= 3 (model 'terpolymer' has 10)" \
  filter --model terpolymer --filters QLF --qlf-expectations cubature
expect_refused "--gh-nodes: must be in 1 .. 40 (got 0)" filter --model sine --gh-nodes 0
expect_refused "--asre-tolerance: must be positive (got -1)" filter --model sine --asre-tolerance -1
expect_refused "--dt: must be positive (got 0)" filter --model sine --dt 0

# A run: summary.json with the metrics and the run's metadata, timeseries.csv per time and filter. Counts may be
# written with an exponent or a decimal point when they are whole numbers (summary.json's members: 200).
"$kushner" filter --model cubic-oscillator --filters QLF,POLY3,ASRE,EKF --members 2e2 --T 0.5 --dt 1e-2 --seed 3 \
  --output-points 5.0 --out "$work/run" --quiet
python3 - "$work/run" <<'PY' || fail "summary.json or timeseries.csv is not what a run must write"
import csv, json, math, sys
run = sys.argv[1]
s = json.load(open(run + "/summary.json"))
for key in ("command", "seed", "version", "git", "backend", "model", "members", "T", "dt", "steps", "filters"):
    assert key in s, key
assert s["seed"] == 3 and s["members"] == 200 and s["steps"] == 50
assert s["filter_order"] == ["EKF", "QLF", "POLY3", "ASRE"], s["filter_order"]
for name, f in s["filters"].items():
    for key in ("rmse_truth", "rmse_truth_se", "nees", "nees_se", "diverged"):
        assert key in f, (name, key)
    assert 0 < f["rmse_truth"] < 10 and 0 < f["rmse_truth_se"] < f["rmse_truth"], (name, f)
assert s["filters"]["QLF"]["expectations"] == "closed"
assert abs(s["filters"]["QLF"]["rmse_truth"] - s["filters"]["POLY3"]["rmse_truth"]) < 1e-9
it = s["filters"]["ASRE"]["iterations"]
assert 1 <= it["min"] <= it["mean"] <= it["max"] <= it["max_iterations"], it
lines = open(run + "/timeseries.csv").read().splitlines()
assert lines[0].startswith("# kushner ") and "seed 3" in lines[0]
rows = list(csv.DictReader(lines[1:]))
assert list(rows[0].keys()) == ["t", "filter", "rmse_truth", "rmse_truth_se", "nees", "nees_se", "diverged"], rows[0].keys()
assert len(rows) == 6 * 4, len(rows)
assert [r["filter"] for r in rows[:4]] == ["EKF", "QLF", "POLY3", "ASRE"]
assert float(rows[0]["t"]) == 0 and float(rows[-1]["t"]) == 0.5
assert all(math.isfinite(float(r["rmse_truth"])) for r in rows)
PY
echo "ok: summary.json and timeseries.csv"

# A config file's counts as TOML floats (members = 2e1 reaches the command line as "20.0"): read as whole numbers.
printf 'members = 2e1\nparticles = 6.4e1\nT = 0.05\ndt = 1e-2\n' >"$work/counts.toml"
"$kushner" filter --model sine --filters EKF,PF --config "$work/counts.toml" --out "$work/counts" --quiet
python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); assert s["members"] == 20, s["members"]' \
  "$work/counts/summary.json" || fail "members = 2e1 in a config file did not run 20 members"
echo "ok: counts as TOML floats in --config"

# "all" beside named references: every supported bank filter, PF, and EXACT; a bad name beside it still refused.
"$kushner" filter --model sine --filters all,EXACT --members 20 --particles 64 --T 0.1 --dt 1e-2 --out "$work/all" --quiet
"$kushner" filters --json >"$work/filters.json"
python3 -c '
import json, sys
order = json.load(open(sys.argv[1]))["filter_order"]
sine = [f["name"] for f in json.load(open(sys.argv[2])) if "sine" in f["models"]]  # report order
assert order == sine + ["PF", "EXACT"], (order, sine)
assert {"EKF", "SOF", "QLF", "ASRE"} <= set(sine) and "KB" not in sine, sine
' "$work/all/summary.json" "$work/filters.json" || fail "--filters all,EXACT is not every bank filter plus PF and EXACT"
expect_refused "filter KB does not support model 'sine' (model is not linear)" filter --model sine --filters all,KB
echo "ok: --filters all,EXACT"

# `kushner filters`: every filter and the models it supports, as text and JSON.
"$kushner" filters >"$work/list.txt"
grep -q '^POLY3 ' "$work/list.txt" || fail "no POLY3 in kushner filters"
grep -q '^    not car: drift is not polynomial$' "$work/list.txt" || fail "kushner filters does not say why POLY3 refuses car"
"$kushner" filters --json | python3 -c '
import json, sys
filters = {f["name"]: f for f in json.load(sys.stdin)}
seeds = ["KB", "EKF", "EKF-DS", "SOF", "SOF-B", "QLF", "POLY3", "POLY4", "BILIN", "MIXED", "ASRE", "KBL"]
assert [n for n in filters if n in seeds] == seeds, list(filters)  # the seed papers filters, in report order
assert filters["QLF"]["options"][1]["name"] == "--gh-nodes" and filters["QLF"]["options"][1]["default"] == 8
assert filters["KB"]["models"] == ["linear", "ou"], filters["KB"]["models"]
assert "terpolymer" in filters["BILIN"]["models"] and "sine" not in filters["POLY3"]["models"]
' || fail "kushner filters --json"
echo "ok: kushner filters"
