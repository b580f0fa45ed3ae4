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


def plot_ucs(runs, report, out):
    """Stress-strain of every UCS run; the best one with its E fit and peak."""
    best = report["best_iteration"]
    it = {i["iteration"]: i for i in report["iterations"]}
    fig, ax = plt.subplots(figsize=(7, 5))
    for name, run in runs.items():
        if run["test"] != "ucs":
            continue
        strain = [1e3 * e for e in col(run, "strain")]
        stress = [s / 1e6 for s in col(run, "stress_Pa")]
        is_best = run["iteration"] == best and not name.startswith("rate")
        label = f"iteration {run['iteration']}" if not name.startswith("rate") else f"iteration {run['iteration']}, half rate"
        ax.plot(strain, stress, lw=2.0 if is_best else 0.8, ls="--" if name.startswith("rate") else "-", label=label)
        if is_best:
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
    t = report["targets"]
    ax.axhline(t["ucs"] / 1e6, color="grey", lw=0.8, ls="-.", label=f"target UCS {t['ucs'] / 1e6:.0f} MPa")
    ax.set_xlabel("axial strain (1e-3)")
    ax.set_ylabel("axial stress (MPa)")
    ax.set_title(f"UCS tests, {report['ore']}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "ucs_stress_strain.png"), dpi=120)
    plt.close(fig)


def plot_brazilian(runs, report, out):
    """Load-displacement of every Brazilian run, peaks marked."""
    best = report["best_iteration"]
    fig, ax = plt.subplots(figsize=(7, 5))
    for name, run in runs.items():
        if run["test"] != "brazilian":
            continue
        d = [1e6 * x for x in col(run, "displacement_m")]
        f = [x / 1e3 for x in col(run, "force_N")]
        st = col(run, "stress_Pa")
        is_best = run["iteration"] == best
        ax.plot(d, f, lw=2.0 if is_best else 0.8, label=f"iteration {run['iteration']}")
        k = max(range(len(f)), key=lambda i: f[i])
        ax.plot(d[k], f[k], "ko" if is_best else "k.")
        if is_best:
            ax.annotate(f"peak {f[k]:.2f} kN, sigma_t {st[k] / 1e6:.2f} MPa", (d[k], f[k]),
                        textcoords="offset points", xytext=(-200, 8))
    ax.set_xlabel("jaw closure (um)")
    ax.set_ylabel("load (kN)")
    ax.set_title(f"Brazilian tests, {report['ore']} (target {report['targets']['tensile_strength'] / 1e6:.1f} MPa)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "brazilian_load_displacement.png"), dpi=120)
    plt.close(fig)


def plot_convergence(report, out):
    """Achieved / target of each property per iteration, with the tolerance band."""
    t = report["targets"]
    tol = report["tolerance"]["relative"]
    its = [i["iteration"] for i in report["iterations"]]
    fig, ax = plt.subplots(figsize=(7, 4))
    for key, name in (("youngs_modulus", "E"), ("poisson_ratio", "nu"), ("ucs", "UCS"),
                      ("tensile_strength", "tensile")):
        ax.plot(its, [i["achieved"][key] / t[key] for i in report["iterations"]], "o-", label=name)
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
    plot_convergence(report, a.out)


if __name__ == "__main__":
    main()
