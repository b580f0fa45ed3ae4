#!/usr/bin/python3
"""The energy ledger of one impact over time, as a stacked area plot.

Reads the impact's energy_ledger.csv (the CSV mirror of impact.h5 /energy,
written by the breakage stage from the run's fix energy/ledger; '#' lines are
comments) and writes one PNG: the energy put in, stacked by where it is at
each time: kinetic (translation and rotation), stored in bonds, released by
broken bonds, element contacts (stored and dissipated), the rigid wall
(elastic and friction), dashpots (bond and wall damping), bond friction,
numerical (the integrator's shadow term) and the residual. The dashed line is
input + work_other (work by moving walls, gas, gravity), which the stack adds
up to. The title gives the comminution efficiency at the end,
bond_released / (input + max(work_other, 0)) (docs/breakage.md).

Usage: plot_energy_ledger.py --ledger energy_ledger.csv --out energy_ledger.png
                             [--title "150 m/s at 90 deg, repeat 0"]
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from plot_breakage import save  # noqa: E402  (same folder: PNG via .tmp and a rename)

# Bands bottom to top: label and the ledger columns they add up.
BANDS = (
    ("kinetic", ("ke_trans_J", "ke_rot_J")),
    ("stored in bonds", ("bond_elastic_J",)),
    ("released by broken bonds", ("bond_released_J",)),
    ("element contacts (stored + friction)", ("contact_elastic_J", "contact_friction_J")),
    ("wall (elastic + friction)", ("wall_elastic_J", "wall_friction_J")),
    ("dashpots (bonds, wall, contacts)", ("bond_damping_J", "wall_damping_J", "contact_damping_J")),
    ("bond friction", ("bond_friction_J",)),
    ("numerical", ("numerical_J",)),
    ("residual", ("residual_J",)),
)
NEEDED = ("time_s", "input_J", "work_other_J") + tuple(c for _, cols in BANDS for c in cols)


def read_ledger(path):
    """The ledger's columns as arrays; exits naming the file, line or column."""
    try:
        with open(path, newline="") as f:
            lines = [(n, line) for n, line in enumerate(f, start=1)
                     if line.strip() and not line.lstrip().startswith("#")]
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e.strerror})")
    if not lines:
        sys.exit(f"{path}: no header line")
    reader = csv.DictReader(line for _, line in lines)
    missing = [c for c in NEEDED if c not in (reader.fieldnames or [])]
    if missing:
        sys.exit(f"{path}:{lines[0][0]}: missing column(s) {', '.join(missing)}")
    cols = {c: [] for c in NEEDED}
    for (line_no, _), row in zip(lines[1:], reader):
        for c in NEEDED:
            try:
                cols[c].append(float(row[c]))
            except (TypeError, ValueError):
                sys.exit(f"{path}:{line_no}: {c}: expected a number, got '{row[c]}'")
    if not cols["time_s"]:
        sys.exit(f"{path}: no rows after the header")
    return {c: np.array(v) for c, v in cols.items()}


def plot(ledger, title, path):
    """The stacked bands against time in ms, with the total put in dashed."""
    t_ms = 1e3 * ledger["time_s"]
    bands = [sum(ledger[c] for c in cols) for _, cols in BANDS]
    total = ledger["input_J"] + ledger["work_other_J"]
    given = ledger["input_J"][-1] + max(ledger["work_other_J"][-1], 0.0)
    efficiency = ledger["bond_released_J"][-1] / given if given > 0 else float("nan")
    fig, ax = plt.subplots(figsize=(8, 4.8))
    colours = plt.get_cmap("tab10").colors
    ax.stackplot(t_ms, *bands, labels=[name for name, _ in BANDS], colors=colours[:len(BANDS)],
                 alpha=0.85)
    ax.plot(t_ms, total, "k--", lw=1.0, label="input + work by walls, gas, gravity")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("energy [J]")
    ax.set_xlim(t_ms[0], t_ms[-1] if t_ms[-1] > t_ms[0] else t_ms[0] + 1e-9)
    ax.set_title(f"Energy ledger{': ' + title if title else ''}\n"
                 f"comminution efficiency {100 * efficiency:.3g}% "
                 f"(released by broken bonds / energy given, at the end)", fontsize=10)
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    order = list(reversed(range(len(BANDS)))) + list(range(len(BANDS), len(handles)))
    ax.legend([handles[k] for k in order], [labels[k] for k in order], fontsize=7,
              loc="center left", bbox_to_anchor=(1.01, 0.5))  # top band first, as stacked
    save(fig, path)


def main(argv=None):
    """Reads --ledger, writes --out."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--ledger", required=True, help="energy_ledger.csv of one impact")
    p.add_argument("--out", required=True, help="the PNG to write")
    p.add_argument("--title", default="", help="the impact, e.g. '150 m/s at 90 deg, repeat 0'")
    a = p.parse_args(argv)
    out_dir = os.path.dirname(os.path.abspath(a.out))
    os.makedirs(out_dir, exist_ok=True)
    plot(read_ledger(a.ledger), a.title, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
