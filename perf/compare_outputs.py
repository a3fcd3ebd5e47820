#!/usr/bin/env python3
"""Two runs' output directories, number by number: the CSV files named and summary.json.

    perf/compare_outputs.py DIR_A DIR_B [FILE.csv ...]   (default: timeseries.csv)

Prints, per file, its rows, the largest relative difference of its numbers (NaN equals NaN; the header, the text fields
and the key columns, a row's time, member and component, must match as written) and whether its bytes below the first
line (the comment with the command, whose --out differs) are the same; then summary.json's numbers (all but backend,
command and timing, which differ between backends and rank counts). Exit 1 when a difference exceeds --tolerance
(default 1e-12), a file's rows or text differ, or summary.json's keys differ.
"""
import argparse
import json
import math
import os
import sys


KEYS = ("t", "member", "component")  # what a row is about: equal as written, not within a tolerance


def header_and_rows(path):
    lines = [line.rstrip("\n").split(",") for line in open(path) if not line.startswith("#")]
    return lines[0], lines[1:]


def field(x):
    try:
        return float(x)
    except ValueError:
        return x


def relative(x, y):
    if math.isnan(x) and math.isnan(y):
        return 0.0
    return abs(x - y) / max(abs(x), abs(y), 1e-300)


def numbers(j, prefix=""):
    if isinstance(j, dict):
        for k, v in j.items():
            if k not in ("backend", "command", "timing"):
                yield from numbers(v, prefix + "." + k)
    elif isinstance(j, (int, float)) and not isinstance(j, bool):
        yield prefix, float(j)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("files", nargs="*", default=["timeseries.csv"])
    parser.add_argument("--tolerance", type=float, default=1e-12)
    args = parser.parse_args()
    worst, ok, lines = 0.0, True, []
    for name in args.files:
        (ha, ra), (hb, rb) = (header_and_rows(os.path.join(d, name)) for d in (args.a, args.b))
        file_worst = 0.0
        if ha != hb or len(ra) != len(rb) or not ra:
            ok = False
            lines.append("%s: header or number of rows differ (%d rows against %d)" % (name, len(ra), len(rb)))
            continue
        keys = {i for i, column in enumerate(ha) if column in KEYS}
        for x_row, y_row in zip(ra, rb):
            ok = ok and len(x_row) == len(y_row) and all(x_row[i] == y_row[i] for i in keys if i < len(x_row))
            for x, y in zip(map(field, x_row), map(field, y_row)):
                if isinstance(x, str) or isinstance(y, str):
                    ok = ok and x == y
                else:
                    file_worst = max(file_worst, relative(x, y))
        below_first = [open(os.path.join(d, name), "rb").read().split(b"\n", 1)[1] for d in (args.a, args.b)]
        lines.append("%s %d rows, largest difference %.3g, same bytes %s" %
                     (name, len(ra), file_worst, below_first[0] == below_first[1]))
        worst = max(worst, file_worst)
    sa, sb = (dict(numbers(json.load(open(os.path.join(d, "summary.json"))))) for d in (args.a, args.b))
    if sa.keys() != sb.keys():
        ok = False
        lines.append("summary.json: keys differ: %s" % sorted(set(sa) ^ set(sb)))
    else:
        summary_worst = max((relative(sa[k], sb[k]) for k in sa), default=0.0)
        lines.append("summary.json %d numbers, largest difference %.3g" % (len(sa), summary_worst))
        worst = max(worst, summary_worst)
    print("; ".join(lines))
    sys.exit(0 if ok and worst <= args.tolerance else 1)


if __name__ == "__main__":
    main()
