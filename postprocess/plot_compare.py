#!/usr/bin/python3
"""Product size curves of several runs on one plot, for `orchestrate compare`.

For each run folder: breakage/product.json (the mill product per rotor speed,
written when the conditions came from the transport stage) is drawn as one
solid curve per rpm; a run without it but with breakage/size_distributions.json
(a velocity sweep) draws each impact condition, averaged over repeats, thin
and dashed. Cumulative % passing against size in mm, log axis; the legend
gives each curve's P80.

Usage: plot_compare.py --run LABEL=RUN_DIR --run LABEL=RUN_DIR ... --out PNG
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402


def load(path):
    """A JSON file, or None when absent; exits naming the file when it does not parse."""
    if not os.path.exists(path):
        return None
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{path}: cannot read as JSON ({e})")


def p80_text(value, finest):
    """'P80 8.1 mm', or 'P80 < 2 mm' when finer than the finest sieve."""
    if value is not None:
        return f"P80 {value:.3g} mm"
    return f"P80 < {finest:.3g} mm"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", action="append", required=True, help="LABEL=RUN_DIR (repeat for each run)")
    p.add_argument("--out", required=True, help="PNG to write")
    a = p.parse_args(argv)
    fig, ax = plt.subplots(figsize=(9, 5))
    drawn = 0
    for k, spec in enumerate(a.run):
        if "=" not in spec:
            sys.exit(f"--run: expected LABEL=RUN_DIR, got '{spec}'")
        label, run = spec.rsplit("=", 1)
        colour = f"C{k}"
        product = load(os.path.join(run, "breakage", "product.json"))
        sizes = load(os.path.join(run, "breakage", "size_distributions.json"))
        if product:
            for j, e in enumerate(sorted(product, key=lambda e: e["rpm"])):
                if "sieves_mm" not in e or "passing_percent" not in e:
                    sys.exit(f"{run}/breakage/product.json: entry {j} lacks sieves_mm or passing_percent "
                             "(rerun the breakage stage with this version)")
                ax.semilogx(e["sieves_mm"], e["passing_percent"], "o-", ms=3, color=colour, alpha=1 - 0.25 * j,
                            label=f"{label}, {e['rpm']:g} rpm ({p80_text(e.get('p80_mm'), e['sieves_mm'][0])})")
                drawn += 1
        elif sizes:
            sieves = sizes["sieves_mm"]
            dashes = ["--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (8, 2))]
            for j, c in enumerate(sizes["conditions"]):
                ax.semilogx(sieves, c["passing_percent"], ls=dashes[j % len(dashes)], lw=1.2, color=colour,
                            label=(f"{label}, {c['velocity_m_s']:g} m/s at {c['angle_deg']:g} deg "
                                   f"({p80_text(c.get('p80_mm'), sieves[0])})"))
                drawn += 1
    if drawn == 0:
        ax.text(0.5, 0.5, "no size distributions in these runs (no breakage stage)", ha="center",
                transform=ax.transAxes)
    ax.axhline(80, color="k", ls=":", lw=0.8)
    ax.set_xlabel("size [mm]")
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda x, _: f"{x:g}" if str(x)[0] in "25" else ""))
    ax.set_ylabel("cumulative mass % passing")
    ax.set_ylim(0, 102)
    ax.set_title("Product size distributions")
    ax.grid(True, which="both", alpha=0.3)
    if drawn:
        ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out + ".tmp", dpi=110, format="png")
    plt.close(fig)
    os.replace(a.out + ".tmp", a.out)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
