#!/usr/bin/env python3
"""Plots and report for a `kushner control` run directory.

usage: control_plots.py DIR

Reads DIR/summary.json and DIR/timeseries.csv as written by `kushner control` and writes PNG and SVG figures plus
DIR/report.md (DIR/reproduction.md, written by `kushner reproduce`, goes into the report when present). Without
matplotlib only report.md is written and the exit status is 3. Figures go through a temporary name and a rename.

  control_paths.{png,svg}  the traced member under each controller: state (solid), the estimate the law used
                           (dashed) per component, and the control
  running_cost.{png,svg}   mean running cost accrued up to t, per controller
  ranking.{png,svg}        J per controller with +-2 standard-error bars, and the reference J* when there is one
"""
import json
import math
import os
import sys

from compare_plots import COLORS, NO_FIGURES, fmt, model_name, read_csv, save, timing_line  # the shared helpers

import compare_plots


def columns(row, prefix):
    keys = sorted((k for k in row if k.startswith(prefix)), key=lambda k: int(k[len(prefix):]))
    return [float(row[k]) for k in keys]


def by_controller(rows):
    out = {}
    for r in rows:
        out.setdefault(r["controller"], []).append(r)
    return out


def plot_paths(plt, directory, summary, series, colors):
    names = summary["controller_order"]
    first = series[names[0]][0]
    n = len(columns(first, "member_state_"))
    m = len(columns(first, "member_control_"))
    fig, axes = plt.subplots(n + m, 1, figsize=(8, 2.4 * (n + m)), sharex=True, squeeze=False)
    for name in names:
        rows = series[name]
        t = [float(r["t"]) for r in rows]
        for i in range(n):
            axes[i][0].plot(t, [columns(r, "member_state_")[i] for r in rows], color=colors[name], label=name)
            if summary["controllers"][name]["estimator"] != "state":
                axes[i][0].plot(t, [columns(r, "member_estimate_")[i] for r in rows], color=colors[name],
                                linestyle="--", linewidth=0.9)
        for j in range(m):
            # A row's control is the one applied over the step that ends at its time (none at t = 0): drawn
            # from the previous output time on.
            axes[n + j][0].step(t[:-1], [columns(r, "member_control_")[j] for r in rows[1:]], where="post",
                                color=colors[name])
    for i in range(n):
        axes[i][0].set_ylabel(f"x{i}")
    for j in range(m):
        axes[n + j][0].set_ylabel(f"u{j}")
    axes[-1][0].set_xlabel("t")
    axes[0][0].legend(fontsize=8)
    axes[0][0].set_title(f"member {summary['trace_member']}: state (solid), estimate used by the law (dashed)")
    save(fig, directory, "control_paths")


def plot_running_cost(plt, directory, summary, series, colors):
    fig, ax = plt.subplots(figsize=(8, 4))
    for name in summary["controller_order"]:
        rows = series[name]
        ax.plot([float(r["t"]) for r in rows], [float(r["running_cost_mean"]) for r in rows], color=colors[name],
                label=name)
    ax.set_xlabel("t")
    ax.set_ylabel("mean running cost accrued")
    ax.legend(fontsize=8)
    save(fig, directory, "running_cost")


def plot_ranking(plt, directory, summary, colors):
    items = sorted(summary["controllers"].items(), key=lambda kv: kv[1]["J"])
    fig, ax = plt.subplots(figsize=(8, 0.5 * len(items) + 1.5))
    for k, (name, c) in enumerate(items):
        ax.errorbar(c["J"], k, xerr=2 * (c["J_se"] or 0.0), fmt="o", color=colors[name], capsize=4)
    ref = summary.get("reference")
    if ref:
        ax.axvline(ref["J"], color="black", linestyle=":", label=f"J* ({ref['kind']})")
        ax.legend(fontsize=8)
    ax.set_yticks(range(len(items)))
    ax.set_yticklabels([name for name, _ in items])
    ax.set_xlabel("expected cost J (±2 SE)")
    save(fig, directory, "ranking")


def write_report(directory, summary, figures, no_figures=None):
    backend = summary.get("backend", {})
    where = backend.get("device") or f"{backend.get('threads', '?')} threads"
    reproduce = summary.get("reproduce")
    title = f"kushner reproduce: {reproduce['example']}" if reproduce else f"kushner control: {model_name(summary)}"
    cost = summary["cost"]
    lines = [f"# {title}", "",
             f"- command: `{summary['command']}`",
             f"- seed {summary['seed']}, kushner {summary['version']} (git {summary.get('git', '?')}), "
             f"backend {backend.get('name', '?')} ({where}), Kokkos {backend.get('kokkos', '?')}",
             f"- members {summary['members']}, T = {summary['T']}, dt = {summary['dt']}; every controller sees the "
             "same initial states and noise (common random numbers)",
             f"- cost: {cost['form']} with F = {cost['F']}, Q = {cost['Q']}, R = {cost['R']}, x* = {cost['target']}"]
    if timing_line(summary):
        lines.append(timing_line(summary))
    ref = summary.get("reference")
    if ref:
        lines.append(f"- reference J* = {ref['J']:.6g} ({ref['kind']}; its discretization error at most "
                     f"{ref['error']:.2g}): the full-information optimum, which no controller beats in expectation")
    reproduction = os.path.join(directory, "reproduction.md")
    if os.path.exists(reproduction):
        with open(reproduction) as f:
            lines += ["", f.read().rstrip("\n")]
    gap = "J − J*" if ref else f"J − J({summary['best']}), paired member by member"
    lines += ["", "## Controllers", "",
              "`J`: expected cost over members (± one Monte Carlo standard error); "
              f"`gap`: {gap}; `energy`: mean ∫|u|² dt; `diverged`: members whose truth escaped or whose estimator "
              "diverged.", "",
              "| controller | J | gap | energy | x(T) mean | diverged |", "|---|---|---|---|---|---|"]
    for name, c in sorted(summary["controllers"].items(), key=lambda kv: kv[1]["J"]):
        terminal = ", ".join(f"{v:.4g}" for v in c["terminal_mean"])
        lines.append(f"| {name} | {fmt(c['J'], c['J_se'])} | {fmt(c['J_gap'], c['J_gap_se'])} | "
                     f"{fmt(c['control_energy'], c['control_energy_se'])} | ({terminal}) | {c['diverged']} |")
    lines += ["", "## Figures", ""]
    if no_figures:
        lines += [f"Not drawn: {no_figures}.", ""]
    captions = {"control_paths": "The traced member under each controller: state, the estimate its law used, "
                                 "and the control.",
                "running_cost": "Mean running cost accrued up to t (the terminal cost comes on top at T).",
                "ranking": "Expected cost per controller with ±2 standard-error bars"
                           + (", and the reference J*." if ref else ".")}
    for name in figures:
        lines += [f"![{name}]({name}.png)", "", captions[name], ""]
    tmp = os.path.join(directory, "report.md.tmp")
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, os.path.join(directory, "report.md"))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    directory = sys.argv[1]
    summary = json.load(open(os.path.join(directory, "summary.json")))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        why = "matplotlib is not installed for " + sys.executable + " (Debian: python3-matplotlib)"
        write_report(directory, summary, [], why)
        print(why)
        sys.exit(NO_FIGURES)
    compare_plots.plt = plt  # save() closes figures through compare_plots' module-level plt
    colors = {n: COLORS[i % len(COLORS)] for i, n in enumerate(summary["controller_order"])}
    series = by_controller(read_csv(os.path.join(directory, "timeseries.csv")))
    plot_paths(plt, directory, summary, series, colors)
    plot_running_cost(plt, directory, summary, series, colors)
    plot_ranking(plt, directory, summary, colors)
    write_report(directory, summary, ["control_paths", "running_cost", "ranking"])


if __name__ == "__main__":
    main()
