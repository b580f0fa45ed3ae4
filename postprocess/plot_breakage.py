#!/usr/bin/python3
"""Plots of a breakage sweep from its aggregated results.

Reads only summary.csv (written by postprocess/breakage_results) and
size_distributions.csv (written by the breakage stage)
and writes, per impact angle, averaged over repeats with the min/max spread:
  pieces_vs_velocity.png      single-element and multi-element pieces vs speed
  largest_vs_velocity.png     largest piece mass fraction vs speed, with the
                              threshold and the critical velocity
  comminution_efficiency_vs_velocity.png
                              comminution efficiency (bond_released over the
                              energy given, from each impact's energy ledger)
                              vs speed, when summary.csv has the column
  passing_vs_size.png         cumulative % passing against size in mm (log
                              axis) per condition, from size_distributions.csv
                              (written by the breakage stage), with --passing
  critical_velocity.json      the speed where the largest piece fraction first
                              falls below the threshold (linear interpolation
                              between sweep points), of the repeat-averaged
                              curve and per repeat (min, max, mean, std)

The critical velocity follows the same rule as FindCriticalVelocity in
postprocess/distributions.h, so the driver and this script agree.

Usage: plot_breakage.py --summary S --out DIR [--passing P]
                        [--threshold 0.05] [--velocities 20,100,150]
"""

import argparse
import csv
import json
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

SUMMARY_NEEDED = ("velocity_m_s", "angle_deg", "repeat", "n_single", "n_multi",
                  "largest_mass_fraction")
EFFICIENCY = "comminution_efficiency"
PASSING_NEEDED = ("velocity_m_s", "angle_deg", "sieve_mm", "passing_percent", "passing_percent_min",
                  "passing_percent_max")

def read_json(path):
    """A results JSON file; exits naming the file (and line) when it cannot be read or parsed."""
    try:
        with open(path) as f:
            return json.load(f)
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e.strerror})")
    except json.JSONDecodeError as e:
        sys.exit(f"{path}:{e.lineno}: not JSON ({e.msg})")


def read_csv(path, needed):
    """Reads a results CSV into a list of dicts of floats; exits naming a missing column."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in needed if c not in (reader.fieldnames or [])]
            if missing:
                sys.exit(f"{path}: missing column(s) {', '.join(missing)}")
            rows = []
            for line_no, row in enumerate(reader, start=2):
                try:
                    rows.append({k: float(row[k]) for k in needed})
                except (TypeError, ValueError):
                    sys.exit(f"{path}:{line_no}: expected numbers in columns {', '.join(needed)}")
            return rows
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e.strerror})")


def first_crossing_below(velocities, values, threshold):
    """Speed where values first fall below threshold, walking up in speed;
    values at one speed are averaged first; linear interpolation between the
    last point at/above and the first below; the first speed if it already is
    below; None if never."""
    by_v = defaultdict(list)
    for v, y in zip(velocities, values):
        by_v[v].append(y)
    prev = None
    for v in sorted(by_v):
        y = sum(by_v[v]) / len(by_v[v])
        if y < threshold:
            if prev is None:
                return v
            v0, y0 = prev
            return v0 + (threshold - y0) * (v - v0) / (y - y0)
        prev = (v, y)
    return None


def critical_velocity(rows, threshold):
    """Critical velocity of the repeat-averaged curve and its spread over repeats."""
    vel = [r["velocity_m_s"] for r in rows]
    val = [r["largest_mass_fraction"] for r in rows]
    per_repeat = {}
    for rep in sorted({int(r["repeat"]) for r in rows}):
        sub = [r for r in rows if int(r["repeat"]) == rep]
        per_repeat[rep] = first_crossing_below([r["velocity_m_s"] for r in sub],
                                               [r["largest_mass_fraction"] for r in sub],
                                               threshold)
    crossed = [c for c in per_repeat.values() if c is not None]
    out = {
        "critical_velocity_m_s": first_crossing_below(vel, val, threshold),
        "per_repeat_m_s": {str(k): v for k, v in per_repeat.items()},
        "n_repeats": len(per_repeat),
        "n_crossed": len(crossed),
        "min_m_s": min(crossed) if crossed else None,
        "max_m_s": max(crossed) if crossed else None,
        "mean_m_s": sum(crossed) / len(crossed) if crossed else None,
        "std_m_s": (math.sqrt(sum((c - sum(crossed) / len(crossed)) ** 2 for c in crossed)
                              / (len(crossed) - 1)) if len(crossed) > 1 else None),
    }
    return out


def stats_by_velocity(rows, key):
    """Speeds ascending, and mean, min, max of rows[key] at each speed."""
    by_v = defaultdict(list)
    for r in rows:
        by_v[r["velocity_m_s"]].append(r[key])
    v = np.array(sorted(by_v))
    vals = [np.array(by_v[x]) for x in v]
    return (v, np.array([a.mean() for a in vals]), np.array([a.min() for a in vals]),
            np.array([a.max() for a in vals]))


def save(fig, path):
    """Writes a figure as PNG via path.tmp and a rename, then closes it."""
    fig.tight_layout()
    fig.savefig(path + ".tmp", dpi=120, format="png")
    os.replace(path + ".tmp", path)
    plt.close(fig)


def angle_label(angle):
    """Legend label of an impact angle (None: conditions of several angles pooled)."""
    return "all conditions" if angle is None else f"{angle:g} deg"


def plot_pieces(by_angle, path):
    """Single- and multi-element piece counts vs speed, mean and min/max."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for angle, rows in sorted(by_angle.items(), key=lambda kv: -1 if kv[0] is None else kv[0]):
        for key, style, name in (("n_single", "o-", "single (fully shredded)"),
                                 ("n_multi", "s--", "multi (partially shredded)")):
            v, mean, lo, hi = stats_by_velocity(rows, key)
            ax.errorbar(v, mean, yerr=[mean - lo, hi - mean], fmt=style, capsize=3,
                        label=f"{name}, {angle_label(angle)}")
    ax.set_xlabel("impact speed [m/s]")
    ax.set_ylabel("number of pieces")
    ax.set_title("Pieces per impact (mean, min-max over repeats)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, path)


def plot_largest(by_angle, critical, threshold, path):
    """Largest piece mass fraction vs speed with the threshold and critical speed."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for angle, rows in sorted(by_angle.items(), key=lambda kv: -1 if kv[0] is None else kv[0]):
        v, mean, lo, hi = stats_by_velocity(rows, "largest_mass_fraction")
        line, = ax.plot(v, mean, "o-", label=f"mean, {angle_label(angle)}")
        ax.fill_between(v, lo, hi, color=line.get_color(), alpha=0.2)
        c = critical[angle]
        if c["critical_velocity_m_s"] is not None:
            ax.axvline(c["critical_velocity_m_s"], color=line.get_color(), ls=":",
                       label=f"critical {c['critical_velocity_m_s']:.1f} m/s")
            if c["min_m_s"] is not None and c["max_m_s"] > c["min_m_s"]:
                ax.axvspan(c["min_m_s"], c["max_m_s"], color=line.get_color(), alpha=0.08)
    ax.axhline(threshold, color="k", ls="--", lw=0.8, label=f"threshold {threshold:g}")
    ax.set_xlabel("impact speed [m/s]")
    ax.set_ylabel("largest piece / lump mass [-]")
    ax.set_ylim(0, 1.05)
    ax.set_title("Largest piece (band: min-max over repeats)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, path)


def plot_efficiency(by_angle, critical, path):
    """Comminution efficiency (%) vs speed, mean and min-max band over repeats,
    with the critical speed of the largest piece marked."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for angle, rows in sorted(by_angle.items(), key=lambda kv: -1 if kv[0] is None else kv[0]):
        v, mean, lo, hi = stats_by_velocity(rows, EFFICIENCY)
        line, = ax.plot(v, 100 * mean, "o-", label=f"mean, {angle_label(angle)}")
        ax.fill_between(v, 100 * lo, 100 * hi, color=line.get_color(), alpha=0.2)
        c = critical.get(angle)
        if c and c["critical_velocity_m_s"] is not None:
            ax.axvline(c["critical_velocity_m_s"], color=line.get_color(), ls=":",
                       label=f"critical {c['critical_velocity_m_s']:.1f} m/s (largest piece)")
    ax.set_xlabel("impact speed [m/s]")
    ax.set_ylabel("comminution efficiency [%]")
    ax.set_ylim(bottom=0)
    ax.set_title("Energy into broken bonds / energy given (band: min-max over repeats)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, path)


def has_column(path, column):
    """True when the CSV's header names the column."""
    try:
        with open(path, newline="") as f:
            return column in (csv.DictReader(f).fieldnames or [])
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e.strerror})")


def plot_passing(passing, velocities, path):
    """Cumulative % passing against size in mm (log axis) per condition, the
    repeat-averaged curve with its min-max band; P80 marked by a line."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    conds = sorted({(r["velocity_m_s"], r["angle_deg"]) for r in passing})
    available = sorted({v for v, _ in conds})
    if velocities:
        chosen = {min(available, key=lambda a: abs(a - w)) for w in velocities}
        conds = [c for c in conds if c[0] in chosen]
    angles = {a for _, a in conds}
    cmap = plt.get_cmap("viridis")
    for k, (vel, angle) in enumerate(conds):
        rows = sorted((r for r in passing if r["velocity_m_s"] == vel and r["angle_deg"] == angle),
                      key=lambda r: r["sieve_mm"])
        size = np.array([r["sieve_mm"] for r in rows])
        colour = cmap(k / max(1, len(conds) - 1) * 0.9)
        label = f"{vel:g} m/s" + (f", {angle:g} deg" if len(angles) > 1 else "")
        ax.semilogx(size, [r["passing_percent"] for r in rows], "o-", ms=3, color=colour, label=label)
        ax.fill_between(size, [r["passing_percent_min"] for r in rows], [r["passing_percent_max"] for r in rows],
                        color=colour, alpha=0.15, lw=0)
    ax.axhline(80, color="k", ls=":", lw=0.8)
    ax.axhline(50, color="k", ls=":", lw=0.8)
    ax.set_xlabel("size [mm] (sieve: upper edge of each size fraction)")
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda x, _: f"{x:g}" if str(x)[0] in "25" else ""))
    ax.set_ylabel("cumulative mass % passing")
    ax.set_ylim(0, 102)
    ax.set_title("Size distribution per impact condition (band: min-max over repeats)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2 if len(conds) > 8 else 1)
    save(fig, path)


def parse_velocities(text):
    """Comma-separated speeds, or an empty list."""
    if not text:
        return []
    try:
        return [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        sys.exit(f"--velocities: expected comma-separated speeds in m/s, got '{text}'")


def main(argv=None):
    """Reads the CSVs, writes the PNGs and critical_velocity.json into --out."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--summary", required=True, help="summary.csv")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--threshold", type=float, default=0.05,
                   help="largest piece fraction below which the lump counts as shattered")
    p.add_argument("--passing", default="", help="size_distributions.csv: draw passing_vs_size.png")
    p.add_argument("--velocities", default="", help="speeds for the passing plot, m/s (default: all)")
    p.add_argument("--pool-angles", action="store_true",
                   help="one curve over all rows (conditions binned from transport: each bin has its own "
                        "speed and angle, so per-angle curves would have one point each)")
    a = p.parse_args(argv)
    if not 0.0 < a.threshold < 1.0:
        sys.exit(f"--threshold: expected a fraction in (0, 1), got {a.threshold}")

    summary = read_csv(a.summary, SUMMARY_NEEDED)
    if not summary:
        sys.exit(f"{a.summary}: no rows")
    os.makedirs(a.out, exist_ok=True)

    by_angle = defaultdict(list)
    for r in summary:
        by_angle[None if a.pool_angles else r["angle_deg"]].append(r)
    critical = {angle: critical_velocity(rows, a.threshold) for angle, rows in by_angle.items()}

    plot_pieces(by_angle, os.path.join(a.out, "pieces_vs_velocity.png"))
    plot_largest(by_angle, critical, a.threshold, os.path.join(a.out, "largest_vs_velocity.png"))
    # Impacts without a ledger (NaN efficiency) are left out; with none, no plot.
    efficiency_png = os.path.join(a.out, "comminution_efficiency_vs_velocity.png")
    with_ledger = []
    if has_column(a.summary, EFFICIENCY):
        with_ledger = [r for r in read_csv(a.summary, SUMMARY_NEEDED + (EFFICIENCY,))
                       if math.isfinite(r[EFFICIENCY])]
    if with_ledger:
        by_angle_eff = defaultdict(list)
        for r in with_ledger:
            by_angle_eff[None if a.pool_angles else r["angle_deg"]].append(r)
        plot_efficiency(by_angle_eff, critical, efficiency_png)
    elif os.path.exists(efficiency_png):
        os.remove(efficiency_png)
    if a.passing:
        passing = read_csv(a.passing, PASSING_NEEDED)
        if not passing:
            sys.exit(f"{a.passing}: no rows")
        plot_passing(passing, parse_velocities(a.velocities), os.path.join(a.out, "passing_vs_size.png"))
    # The superseded bar chart of mass per fraction, if an older run left one.
    old = os.path.join(a.out, "mass_distribution.png")
    if os.path.exists(old):
        os.remove(old)

    out = {"threshold": a.threshold,
           "quantity": "largest_mass_fraction",
           "angles": {("all" if angle is None else f"{angle:g}"): c
                      for angle, c in sorted(critical.items(), key=lambda kv: -1 if kv[0] is None else kv[0])}}
    path = os.path.join(a.out, "critical_velocity.json")
    with open(path + ".tmp", "w") as f:
        json.dump(out, f, indent=2)
        f.write("\n")
    os.replace(path + ".tmp", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
