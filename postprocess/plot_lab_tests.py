#!/usr/bin/env python3
"""Plots of the calibrate stage: stress-strain curves of the UCS tests with the
fitted E and the peaks marked, load-displacement curves of the Brazilian tests
with the peak loads, and the convergence of the macro properties.

Reads only the aggregated results (curves.csv and report.json written by the
stage), never the engine logs:
    plot_lab_tests.py --curves curves.csv --report report.json --out plots/
"""
import argparse
import csv
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_curves(path):
    """Rows of curves.csv grouped by run name, in file order."""
    runs = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            r = runs.setdefault(row["run"], {"iteration": int(row["iteration"]), "test": row["test"],
                                             "rate": float(row["strain_rate"]), "rows": []})
            r["rows"].append({k: float(row[k]) for k in ("displacement_m", "force_N", "strain", "stress_Pa",
                                                         "lateral_strain")})
    return runs


def col(run, key):
    """One column of a run as a list."""
    return [r[key] for r in run["rows"]]


def plot_test_curves(runs, report, out, test, x, y, mark, xlabel, ylabel, title, filename, decorate=None):
    """One figure with every run of one lab test (curves.csv `test` column):
    x and y are (column, convert) pairs; the best iteration's run is drawn thick
    and a rate-check run (name `rate...`) dashed; mark(ax, run, xs, ys, is_best)
    adds the test's own peak and fit marks after each curve, decorate(ax) any
    reference lines after all curves."""
    best = report["best_iteration"]
    fig, ax = plt.subplots(figsize=(7, 5))
    for name, run in runs.items():
        if run["test"] != test:
            continue
        xs = [x[1](v) for v in col(run, x[0])]
        ys = [y[1](v) for v in col(run, y[0])]
        is_rate = name.startswith("rate")
        is_best = run["iteration"] == best and not is_rate
        label = f"iteration {run['iteration']}, half rate" if is_rate else f"iteration {run['iteration']}"
        ax.plot(xs, ys, lw=2.0 if is_best else 0.8, ls="--" if is_rate else "-", label=label)
        mark(ax, run, xs, ys, is_best)
    if decorate:
        decorate(ax)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, filename), dpi=120)
    plt.close(fig)


def plot_ucs(runs, report, out):
    """Stress-strain of every UCS run; the best one with its E fit and peak."""
    best = report["best_iteration"]
    it = {i["iteration"]: i for i in report["iterations"]}

    def mark(ax, run, strain, stress, is_best):
        if not is_best:
            return
        k = max(range(len(stress)), key=lambda i: stress[i])
        ax.plot(strain[k], stress[k], "ko")
        ax.annotate(f"UCS {stress[k]:.1f} MPa", (strain[k], stress[k]), textcoords="offset points", xytext=(-60, 10))
        E = it[best]["achieved"]["youngs_modulus"]
        lo, hi = it[best]["ucs_fit_window_Pa"]
        # the fitted line over the fit window
        xs = [e for e, s in zip(strain, stress) if lo / 1e6 <= s <= hi / 1e6][:1]
        if xs:
            x0 = xs[0]
            s0 = stress[strain.index(x0)]
            x1 = x0 + (hi - lo) / E * 1e3
            ax.plot([x0, x1], [s0, s0 + (x1 - x0) * E / 1e9], "k:", lw=2,
                    label=f"E = {E / 1e9:.2f} GPa (fit {lo / 1e6:.1f}-{hi / 1e6:.1f} MPa)")

    def decorate(ax):
        t = report["targets"]
        ax.axhline(t["ucs"] / 1e6, color="grey", lw=0.8, ls="-.", label=f"target UCS {t['ucs'] / 1e6:.0f} MPa")

    plot_test_curves(runs, report, out, "ucs",
                     x=("strain", lambda e: 1e3 * e), y=("stress_Pa", lambda s: s / 1e6), mark=mark,
                     xlabel="axial strain (1e-3)", ylabel="axial stress (MPa)",
                     title=f"UCS tests, {report['ore']}", filename="ucs_stress_strain.png", decorate=decorate)


def plot_brazilian(runs, report, out):
    """Load-displacement of every Brazilian run, peaks marked."""

    def mark(ax, run, d, f, is_best):
        st = col(run, "stress_Pa")
        k = max(range(len(f)), key=lambda i: f[i])
        ax.plot(d[k], f[k], "ko" if is_best else "k.")
        if is_best:
            ax.annotate(f"peak {f[k]:.2f} kN, sigma_t {st[k] / 1e6:.2f} MPa", (d[k], f[k]),
                        textcoords="offset points", xytext=(-200, 8))

    t = report["targets"]
    # With the direct tension test as the tensile target the disc is a check
    # against the card's Brazilian strength (calibrate.tensile_test direct).
    direct = t.get("tensile_test") == "direct"
    target = (f"card {t['brazilian_tensile_strength'] / 1e6:.1f} MPa, a check" if direct
              else f"target {t['tensile_strength'] / 1e6:.1f} MPa")
    plot_test_curves(runs, report, out, "brazilian",
                     x=("displacement_m", lambda x: 1e6 * x), y=("force_N", lambda x: x / 1e3), mark=mark,
                     xlabel="jaw closure (um)", ylabel="load (kN)",
                     title=f"Brazilian tests, {report['ore']} ({target})",
                     filename="brazilian_load_displacement.png")


def plot_tension(runs, report, out):
    """Stress-strain of every direct tension run (calibrate.tensile_test
    direct), peaks marked; nothing when none ran."""
    if not any(run["test"] == "tension" for run in runs.values()):
        return

    def mark(ax, run, strain, stress, is_best):
        k = max(range(len(stress)), key=lambda i: stress[i])
        ax.plot(strain[k], stress[k], "ko" if is_best else "k.")
        if is_best:
            ax.annotate(f"peak {stress[k]:.2f} MPa", (strain[k], stress[k]), textcoords="offset points",
                        xytext=(-60, 10))

    def decorate(ax):
        t = report["targets"]["tensile_strength"]
        ax.axhline(t / 1e6, color="grey", lw=0.8, ls="-.", label=f"target {t / 1e6:.2f} MPa")

    plot_test_curves(runs, report, out, "tension",
                     x=("strain", lambda e: 1e3 * e), y=("stress_Pa", lambda s: s / 1e6), mark=mark,
                     xlabel="axial strain (1e-3)", ylabel="tensile stress (MPa)",
                     title=f"Direct tension tests, {report['ore']}", filename="tension_stress_strain.png",
                     decorate=decorate)


def plot_convergence(report, out):
    """Achieved / target of each property per iteration, with the tolerance band
    (K_IC too when the fit aimed at it: calibrate.fit_toughness)."""
    t = report["targets"]
    tol = report["tolerance"]["relative"]
    its = [i["iteration"] for i in report["iterations"]]
    fig, ax = plt.subplots(figsize=(7, 4))
    props = [("youngs_modulus", "E"), ("poisson_ratio", "nu"), ("ucs", "UCS"),
             ("tensile_strength", "direct tensile" if t.get("tensile_test") == "direct" else "tensile")]
    if "fracture_toughness" in t:
        props.append(("fracture_toughness", "K_IC"))
    for key, name in props:
        # An iteration without a measurement (null: e.g. a Brazilian disc that
        # did not split) leaves a gap in its line.
        ratio = [float("nan") if i["achieved"].get(key) is None else i["achieved"][key] / t[key]
                 for i in report["iterations"]]
        ax.plot(its, ratio, "o-", label=name)
    ax.axhspan(1 - tol, 1 + tol, color="green", alpha=0.15, label=f"+-{100 * tol:.0f}%")
    ax.set_xlabel("iteration")
    ax.set_ylabel("achieved / target")
    ax.set_yscale("log")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "convergence.png"), dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curves", required=True)
    ap.add_argument("--report", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(a.report) as f:
        report = json.load(f)
    runs = read_curves(a.curves)
    plot_ucs(runs, report, a.out)
    plot_brazilian(runs, report, a.out)
    plot_tension(runs, report, a.out)
    plot_convergence(report, a.out)


if __name__ == "__main__":
    main()
