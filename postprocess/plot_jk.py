#!/usr/bin/python3
"""t10 against the specific impact energy, with the JK fit, from a breakage sweep.

Reads jk_points.csv (every impact: angle, speed, repeat, Ecs in kWh/t, t10 in
%, whether t10 is resolved) and jk_fit.json (per impact angle, or all
conditions pooled: A, b, A x b and their spread over repeats, and the ore
card's measured A and b if it has them), both written by the breakage stage,
and draws jk_t10_vs_ecs.png:

  points   impacts whose t10 is resolved (used in the fit), one marker per
           repeat; impacts whose t10 is not resolved, hollow and grey (not
           used: single elements are coarser than a tenth of the lump)
  lines    the fit t10 = A (1 - exp(-b Ecs)) (Napier-Munn et al. 1996) per
           angle, and dashed the ore card's measured A and b

Usage: plot_jk.py --points jk_points.csv --fit jk_fit.json --out DIR
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from plot_breakage import read_csv, read_json  # noqa: E402  (same folder: the results readers)

POINT_COLUMNS = ("angle_deg", "velocity_m_s", "repeat", "ecs_kWh_t", "t10_percent", "t10_resolved")


def read_points(path):
    """The rows of jk_points.csv as dicts of floats; exits naming a missing column or bad cell."""
    return read_csv(path, POINT_COLUMNS)


def read_fit(path):
    """jk_fit.json: a list with one entry per angle (angle_deg null: pooled)."""
    data = read_json(path)
    if not isinstance(data, list):
        sys.exit(f"{path}: expected a list of fits (one per impact angle)")
    for i, e in enumerate(data):
        if "fitted" not in e or "angle_deg" not in e:
            sys.exit(f"{path}: entry {i} lacks 'fitted' or 'angle_deg'")
        if e["fitted"] and not all(k in e for k in ("A_percent", "b_t_per_kWh")):
            sys.exit(f"{path}: entry {i} is fitted but lacks A_percent or b_t_per_kWh")
    return data


def jk(a, b, ecs):
    """t10 of the JK relation."""
    return a * (1.0 - np.exp(-b * ecs))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--points", required=True, help="breakage/jk_points.csv")
    p.add_argument("--fit", required=True, help="breakage/jk_fit.json")
    p.add_argument("--out", required=True, help="folder for jk_t10_vs_ecs.png")
    a = p.parse_args(argv)
    points = read_points(a.points)
    fits = read_fit(a.fit)
    os.makedirs(a.out, exist_ok=True)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    e_max = max([r["ecs_kWh_t"] for r in points] + [0.1])
    grid = np.linspace(0.0, 1.05 * e_max, 200)
    markers = "os^Dv<>p*h"
    card = None
    for k, fit in enumerate(fits):
        angle = fit["angle_deg"]
        mine = [r for r in points if angle is None or r["angle_deg"] == angle]
        where = "" if angle is None else f", {angle:g} deg"
        colour = f"C{k}"
        reps = sorted({int(r["repeat"]) for r in mine})
        for j, rep in enumerate(reps):
            used = [r for r in mine if int(r["repeat"]) == rep and r["t10_resolved"] > 0]
            if used:
                ax.plot([r["ecs_kWh_t"] for r in used], [r["t10_percent"] for r in used], markers[j % len(markers)],
                        color=colour, ms=5, label=f"repeat {rep}{where}")
        skipped = [r for r in mine if r["t10_resolved"] <= 0]
        if skipped:
            ax.plot([r["ecs_kWh_t"] for r in skipped], [r["t10_percent"] for r in skipped], "o", mfc="none",
                    color="0.6", ms=5, label=f"t10 not resolved (not used){where}")
        if fit["fitted"]:
            A, b = fit["A_percent"], fit["b_t_per_kWh"]
            ax.plot(grid, jk(A, b, grid), "-", color=colour,
                    label=f"fit{where}: A {A:.1f}%, b {b:.3g} t/kWh, A x b {A * b:.3g}")
        card = card or fit.get("ore_card")
    if card:
        A, b = card["A_percent"], card["b_t_per_kWh"]
        ax.plot(grid, jk(A, b, grid), "--", color="k", lw=1,
                label=f"ore card (measured): A {A:g}%, b {b:g} t/kWh, A x b {A * b:.3g}")
    if not any(f["fitted"] for f in fits):
        reason = next((f.get("reason") for f in fits if f.get("reason")), "no fit")
        ax.text(0.02, 0.97, "no fit: " + reason, transform=ax.transAxes, va="top", fontsize=7, wrap=True,
                color="0.3")
    ax.set_xlabel("specific impact energy Ecs = V$^2$/2 [kWh/t]")
    ax.set_ylabel("t10 [% finer than a tenth of the lump]")
    ax.set_xlim(0, 1.05 * e_max)
    ax.set_ylim(0, 100)
    ax.set_title("JK breakage: t10 = A (1 - exp(-b Ecs))")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    path = os.path.join(a.out, "jk_t10_vs_ecs.png")
    fig.savefig(path + ".tmp", dpi=110, format="png")
    plt.close(fig)
    os.replace(path + ".tmp", path)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
