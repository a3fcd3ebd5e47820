#!/usr/bin/env python3
"""Plots and report for a `kushner compare` run directory.

usage: compare_plots.py DIR

Reads DIR/summary.json, DIR/timeseries.csv, DIR/trajectories.csv and DIR/density.csv, as written
by `kushner compare`, and writes PNG and SVG figures plus DIR/report.md; DIR/reproduction.md (written by
`kushner reproduce`) goes into the report when present. Without matplotlib only report.md is written (its
tables, and a line saying why there are no figures) and the exit status is 3. Figures are written through a temporary name and
renamed, like every kushner output.

  estimates.{png,svg}  one member: truth, each filter's estimate, the particle mean and its 5-95% band (one
                       panel per state component, up to 3); the filters' +-2 sigma bands are in trajectories.csv
  errors.{png,svg}     RMS error to the truth against time, per filter (and to the particle mean, dashed)
  rmse_ref.{png,svg}   bar chart of rmse_ref per filter with +-2 standard-error bars
  density.{png,svg}    the particle density of x1 (its marginal) at chosen times with each filter's Gaussian,
                       and the most bimodal one the run saw
"""
import csv
import json
import math
import os
import sys
from collections import defaultdict

plt = None  # matplotlib.pyplot, imported by main(): without matplotlib report.md is still written

NO_FIGURES = 3  # exit status: report.md written, figures not drawn (the last line of output says why)

COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
          "#bcbd22", "#17becf", "#393b79", "#637939"]


def read_csv(path):
    """Rows of a CSV file as dicts, skipping the leading '#' comment line."""
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def save(fig, directory, name):
    for ext in ("png", "svg"):
        tmp = os.path.join(directory, f"{name}.tmp.{ext}")
        fig.savefig(tmp, dpi=130, bbox_inches="tight")
        os.replace(tmp, os.path.join(directory, f"{name}.{ext}"))
    plt.close(fig)


def reference_name(summary):
    """What rmse_ref measures against, for labels: the particle filter unless the run says otherwise."""
    ref = summary.get("reference") or {}
    return "particle-filter" if ref.get("kind", "particle filter") == "particle filter" else ref.get("name", "reference")


def color_of(names):
    return {n: COLORS[i % len(COLORS)] for i, n in enumerate(names)}


def plot_estimates(directory, summary, rows, colors):
    """Truth, estimates with +-2 sigma bands and the particle band, for the first member in trajectories.csv."""
    member = rows[0]["member"]
    rows = [r for r in rows if r["member"] == member]
    components = sorted({int(r["component"]) for r in rows})[:3]
    fig, axes = plt.subplots(len(components), 1, figsize=(9, 3.2 * len(components)), squeeze=False, sharex=True)
    for ax, c in zip(axes[:, 0], components):
        by_series = defaultdict(list)
        for r in rows:
            if int(r["component"]) == c:
                by_series[r["series"]].append(r)
        truth = by_series.pop("truth", [])
        reference = by_series.pop("PF", None)
        if reference:
            t = [float(r["t"]) for r in reference]
            ax.fill_between(t, [float(r["lower"]) for r in reference], [float(r["upper"]) for r in reference],
                            color="0.85", label="particle filter 5-95%")
            ax.plot(t, [float(r["estimate"]) for r in reference], color="0.35", lw=1.2, label="particle mean")
        for name, series in by_series.items():  # bands of many filters would hide each other: lines only
            t = [float(r["t"]) for r in series]
            ax.plot(t, [float(r["estimate"]) for r in series], color=colors.get(name), lw=1.0, label=name)
        if truth:
            ax.plot([float(r["t"]) for r in truth], [float(r["estimate"]) for r in truth], color="k", lw=1.6,
                    ls=":", label="truth")
        ax.set_ylabel(f"x{c}")
        ax.grid(alpha=0.3)
    band = " and the particle filter's 5-95% band" if any(r["series"] == "PF" for r in rows) else ""
    axes[0, 0].set_title(f"{model_name(summary)}: member {member}, estimates{band}")
    axes[-1, 0].set_xlabel("t")
    axes[0, 0].legend(fontsize=7, ncol=4, loc="upper right")
    save(fig, directory, "estimates")


def plot_errors(directory, summary, rows, colors):
    """Ensemble RMS error to the truth (solid) and to the particle mean (dashed) against time."""
    by_filter = defaultdict(list)
    for r in rows:
        by_filter[r["filter"]].append(r)
    fig, ax = plt.subplots(figsize=(9, 4.2))
    for name, series in by_filter.items():
        t = [float(r["t"]) for r in series]
        ax.plot(t, [float(r["rmse_truth"]) for r in series], color=colors.get(name, "0.3"), lw=1.2, label=name)
        if "rmse_ref" in series[0] and series[0]["rmse_ref"] not in ("", "nan"):
            ax.plot(t, [float(r["rmse_ref"]) for r in series], color=colors.get(name, "0.3"), lw=0.9, ls="--")
    ax.set_yscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("RMS error over members")
    ax.set_title(f"error to the truth (solid) and to the {reference_name(summary)} mean (dashed)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, ncol=4)
    save(fig, directory, "errors")


def plot_rmse_ref(directory, summary, colors):
    filters = [(n, f) for n, f in summary["filters"].items() if f.get("rmse_ref") is not None and n != "PF"]
    if not filters:
        return False
    filters.sort(key=lambda nf: nf[1]["rmse_ref"])
    fig, ax = plt.subplots(figsize=(max(5, 0.9 * len(filters) + 2), 4))
    names = [n for n, _ in filters]
    ax.bar(names, [f["rmse_ref"] for _, f in filters], yerr=[2 * (f.get("rmse_ref_se") or 0.0) for _, f in filters],
           color=[colors.get(n) for n in names], capsize=4)
    ax.set_ylabel(f"RMS distance to {reference_name(summary)} mean")
    ax.set_title("approximation error against the true conditional mean (+-2 SE)")
    ax.grid(alpha=0.3, axis="y")
    save(fig, directory, "rmse_ref")
    return True


def plot_density(directory, summary, rows, colors):
    state_dim = int(summary.get("model", {}).get("state_dim", 1))
    # Panels: the snapshots at the chosen times, then the most bimodal posterior the run saw.
    panels = sorted({(r["snapshot"] != "time", float(r["t"]), r["member"]) for r in rows})
    fig, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels), 3.4), squeeze=False)
    bimodal = summary.get("density", {}).get("most_bimodal", {})
    for ax, (scanned, t, member) in zip(axes[0], panels):
        by_series = defaultdict(list)
        for r in rows:
            if (r["snapshot"] != "time", float(r["t"]), r["member"]) == (scanned, t, member):
                by_series[r["series"]].append((float(r["x"]), float(r["density"])))
        pf = by_series.pop("PF", [])
        if pf:
            xs, ds = zip(*pf)
            width = (xs[1] - xs[0]) if len(xs) > 1 else 1.0
            ax.bar(xs, ds, width=width, color="0.8", label="particle filter")
        for name, points in by_series.items():
            if name == "truth":
                ax.axvline(points[0][0], color="k", ls=":", label="truth")
                continue
            xs, ds = zip(*points)
            ax.plot(xs, ds, color=colors.get(name), lw=1.1, label=name)
        if scanned:
            ax.set_title(f"most bimodal: member {member}, t = {t:g}\n(score {bimodal.get('score', 0):.2f} of "
                         f"{bimodal.get('scanned_members', '?')} members)", fontsize=9)
        else:
            ax.set_title(f"member {member}, t = {t:g}")
        ax.set_xlabel("x" if state_dim == 1 else "x1")
    axes[0][0].set_ylabel("conditional density" if state_dim == 1 else "conditional density of x1 (marginal)")
    axes[0][0].legend(fontsize=7)
    save(fig, directory, "density")


def fmt(value, se=None):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return f"{value:.4g} ± {se:.2g}" if se is not None else f"{value:.4g}"


def model_name(summary):
    """The model's name; for a --model-file model, the file's own name (or path) after it."""
    model = summary["model"]
    if "file" in model:
        return f"{model['name']} ({model.get('label', model['file'])})"
    return model["name"]


def timing_line(summary):
    """The report's line on speed, from summary.json's "timing" (None without it)."""
    t = summary.get("timing")
    if not t:
        return None
    rates = f"{t['member_steps_per_s']:.3g} member-steps/s"
    if "particle_steps_per_s" in t:
        rates += f", {t['particle_steps_per_s']:.3g} particle-steps/s"
    return (f"- wall time: step loop {t['step_loop_s']:.3g} s ({rates}); whole command {t['command_s']:.3g} s "
            "up to the results (figures not included)")


def write_report(directory, summary, figures, no_figures=None):
    backend = summary.get("backend", {})
    where = backend.get("device") or f"{backend.get('threads', '?')} threads"
    reproduce = summary.get("reproduce")
    title = f"kushner reproduce: {reproduce['example']}" if reproduce else f"kushner compare: {model_name(summary)}"
    lines = [f"# {title}", "",
             f"- command: `{summary['command']}`",
             f"- seed {summary['seed']}, kushner {summary['version']} (git {summary.get('git', '?')}), "
             f"backend {backend.get('name', '?')} ({where}), Kokkos {backend.get('kokkos', '?')}",
             f"- members {summary['members']}, T = {summary['T']}, dt = {summary['dt']}"]
    if timing_line(summary):
        lines.append(timing_line(summary))
    memory = summary.get("memory")
    if memory:
        pf = memory["particle_bytes_per_particle"]
        lines.append(f"- memory: {memory['total_bytes'] / 2**20:.4g} MiB for the banks "
                     f"({memory['bank_bytes_per_member']:.0f} B per member"
                     + (f", {pf:.0f} B per particle of the particle filter)" if pf else ")"))
    if "file" in summary["model"]:
        lines.append(f"- model file: `{summary['model']['file']}` (coefficients in summary.json)")
    truth = summary.get("truth")
    if truth:
        lines.append(f"- truths: `{truth['name']}` model, observation noise {truth['observation_noise']}; filters: "
                     f"`{summary['model']['name']}` model")
    bimodal = summary.get("density", {}).get("most_bimodal")
    if bimodal and bimodal.get("member", -1) >= 0:
        verdict = ("bimodal" if bimodal["score"] >= 0.25 else
                   "no clearly bimodal posterior (a score below 0.25: one mode, or a second one lost in the noise)")
        lines.append(f"- most bimodal particle posterior of x1 among members 0–{bimodal['scanned_members'] - 1} at "
                     f"the output times: member {bimodal['member']} at t = {bimodal['t']:g}, score "
                     f"{bimodal['score']:.2f} (the second mode's height over the first's): {verdict}")
    ref = summary.get("reference")
    if ref:
        if ref.get("kind") == "particle filter":
            lines.append(f"- reference: particle filter with {ref.get('particles')} particles per member "
                         f"({ref.get('resampling')} resampling below ESS {ref.get('ess_threshold')} N, "
                         f"{ref.get('precision', 'fp64')} precision), mean ESS "
                         f"{fmt(ref.get('mean_ess'))}, resampling events {ref.get('resamples')}; its own Monte Carlo "
                         f"error (noise floor of rmse_ref) {fmt(ref.get('noise_floor'))}")
        else:
            lines.append(f"- reference: {ref.get('kind')} ({ref.get('note', '')})")
    reproduction = os.path.join(directory, "reproduction.md")
    if os.path.exists(reproduction):
        with open(reproduction) as f:
            lines += ["", f.read().rstrip("\n")]
    reference = "the particle-filter" if not ref or ref.get("kind") == "particle filter" else "the reference's"
    lines += ["", "## Metrics", "",
              f"`rmse_ref`: RMS distance to {reference} posterior mean (the approximation error against the "
              "true conditional density); `rmse_truth`: RMS error to the simulated truth; `nees`: mean normalized "
              "estimation error squared (the state dimension when the filter's covariance is honest); `diverged`: "
              "members whose covariance lost positive definiteness or whose values became non-finite. "
              "± one Monte Carlo standard error over members.", "",
              "| filter | rmse_ref | rmse_truth | nees | diverged |", "|---|---|---|---|---|"]
    rows = sorted(summary["filters"].items(),
                  key=lambda nf: (nf[1].get("rmse_ref") is None, nf[1].get("rmse_ref") or 0.0))
    for name, f in rows:
        lines.append(f"| {name} | {fmt(f.get('rmse_ref'), f.get('rmse_ref_se'))} | "
                     f"{fmt(f.get('rmse_truth'), f.get('rmse_truth_se'))} | {fmt(f.get('nees'), f.get('nees_se'))} | "
                     f"{f.get('diverged', 0)} |")
    lines += ["", "## Figures", ""]
    if no_figures:
        lines += [f"Not drawn: {no_figures}.", ""]
    particle = reference == "the particle-filter"
    captions = {"estimates": "One member: truth, each filter's estimate" +
                             (", particle mean with its 5–95% band" if particle else "") +
                             " (the filters' ±2σ bands are in trajectories.csv).",
                "errors": "RMS error over members against time: to the truth (solid), to the " +
                          ("particle" if particle else "reference's") + " mean (dashed).",
                "rmse_ref": "Approximation error per filter, with ±2 standard-error bars.",
                "density": "Particle density (histogram) against each filter's Gaussian: one member at chosen "
                           "times, and the most bimodal posterior seen (last panel), which no Gaussian can follow."}
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
    global plt
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        why = "matplotlib is not installed for " + sys.executable + " (Debian: python3-matplotlib)"
        write_report(directory, summary, [], why)
        print(why)
        sys.exit(NO_FIGURES)
    colors = color_of([n for n in summary["filters"] if n != "PF"])
    figures = []
    trajectories = os.path.join(directory, "trajectories.csv")
    if os.path.exists(trajectories):
        plot_estimates(directory, summary, read_csv(trajectories), colors)
        figures.append("estimates")
    plot_errors(directory, summary, read_csv(os.path.join(directory, "timeseries.csv")), colors)
    figures.append("errors")
    if plot_rmse_ref(directory, summary, colors):
        figures.append("rmse_ref")
    density = os.path.join(directory, "density.csv")
    if os.path.exists(density):
        plot_density(directory, summary, read_csv(density), colors)
        figures.append("density")
    write_report(directory, summary, figures)


if __name__ == "__main__":
    main()
