#!/usr/bin/python3
"""The mill product against rotor speed, from breakage/product.json.

product.json (written by the breakage stage when its conditions come from the
transport stage) holds, per rotor speed, the product of one pass: the mass per
size fraction, the cumulative % passing each sieve (mm) with P50 and P80, the
fully shredded (single-element) mass share, the largest piece and t10. This
draws product_vs_rpm.png:

  left    P80 and P50 of the product [mm] against rpm (a point finer than the
          finest sieve is drawn at that sieve, hollow)
  middle  fully shredded mass %, largest piece % and t10 % against rpm: where
          these flatten, the rotor speed can be lowered for the same product
  right   the product's cumulative % passing against size [mm], log axis, per rpm

Where an entry has an `in_mill` object (breakage.in_mill: bonded lumps run in
the turning mill from their first flywheel strike, with the housing impacts
that follow), its values are drawn on the same axes, dashed with hollow
markers and labelled "in mill", beside the single-impact product.

Usage: plot_product.py --product breakage/product.json --out breakage/plots
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402
from plot_breakage import read_json  # noqa: E402  (same folder: the results-JSON reader)

NEEDED = ("rpm", "fraction_edges_rel", "fraction_mass", "fully_shredded_mass_fraction",
          "largest_piece_mass_fraction", "t10_percent", "sieves_mm", "passing_percent", "p50_mm", "p80_mm")


def read_product(path):
    data = read_json(path)
    if not isinstance(data, list) or not data:
        sys.exit(f"{path}: expected a non-empty list of per-rpm products")
    for i, e in enumerate(data):
        missing = [k for k in NEEDED if k not in e]
        if missing:
            sys.exit(f"{path}: entry {i} lacks {', '.join(missing)}")
        if len(e["fraction_edges_rel"]) != len(e["fraction_mass"]) + 1:
            sys.exit(f"{path}: entry {i}: {len(e['fraction_edges_rel'])} edges for "
                     f"{len(e['fraction_mass'])} fractions")
        if len(e["sieves_mm"]) != len(e["passing_percent"]):
            sys.exit(f"{path}: entry {i}: {len(e['sieves_mm'])} sieves for {len(e['passing_percent'])} passing values")
        if "in_mill" in e:
            missing = [k for k in ("fully_shredded_mass_fraction", "largest_piece_mass_fraction", "t10_percent",
                                   "sieves_mm", "passing_percent", "p50_mm", "p80_mm") if k not in e["in_mill"]]
            if missing:
                sys.exit(f"{path}: entry {i}: in_mill lacks {', '.join(missing)}")
    return sorted(data, key=lambda e: e["rpm"])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--product", required=True, help="breakage/product.json")
    p.add_argument("--out", required=True, help="folder for product_vs_rpm.png")
    a = p.parse_args(argv)
    data = read_product(a.product)
    os.makedirs(a.out, exist_ok=True)

    rpm = np.array([e["rpm"] for e in data])
    fig, (ax0, ax1, ax2) = plt.subplots(1, 3, figsize=(14, 4.3))
    colour = {}
    for key, label, style in (("p80_mm", "P80", "o-"), ("p50_mm", "P50", "s--")):
        ys = [e[key] if e[key] is not None else e["sieves_mm"][0] for e in data]
        line, = ax0.plot(rpm, ys, style, label=label)
        colour[key] = line.get_color()
        below = [(r, y) for r, y, e in zip(rpm, ys, data) if e[key] is None]
        if below:
            ax0.plot([b[0] for b in below], [b[1] for b in below], "o", mfc="white", color=line.get_color(),
                     label=f"{label} finer than the finest sieve")
    mill = [e for e in data if "in_mill" in e]
    mill_rpm = np.array([e["rpm"] for e in mill])
    for key, label, style in (("p80_mm", "P80 in mill", "o:"), ("p50_mm", "P50 in mill", "s:")):
        if mill:
            ys = [e["in_mill"][key] if e["in_mill"][key] is not None else e["in_mill"]["sieves_mm"][0] for e in mill]
            ax0.plot(mill_rpm, ys, style, mfc="white", color=colour[key], label=label)
    ax0.set_xlabel("rotor speed [rpm]")
    ax0.set_ylabel("size [mm]")
    ax0.set_ylim(bottom=0)
    ax0.set_title("Product size: P80 and P50")
    ax0.legend(fontsize=8)
    ax0.grid(alpha=0.3)

    for key, label, scale in (("fully_shredded_mass_fraction", "fully shredded mass", 100),
                              ("largest_piece_mass_fraction", "largest piece", 100),
                              ("t10_percent", "t10 (finer than D/10)", 1)):
        line, = ax1.plot(rpm, [scale * e[key] for e in data], "o-", label=label)
        if mill:
            ax1.plot(mill_rpm, [scale * e["in_mill"][key] for e in mill], "o:", mfc="white", color=line.get_color(),
                     label=f"{label}, in mill")
    ax1.set_xlabel("rotor speed [rpm]")
    ax1.set_ylabel("% of the feed mass")
    ax1.set_ylim(-2, 102)
    for ax in (ax0, ax1):
        if len(rpm) == 1:
            ax.set_xlim(rpm[0] * 0.8, rpm[0] * 1.2)
    ax1.set_title("One pass: single impact" + (" and in mill" if mill else ""))
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)

    for e in data:
        line, = ax2.semilogx(e["sieves_mm"], e["passing_percent"], "o-", ms=3, label=f"{e['rpm']:g} rpm")
        if "in_mill" in e:
            m = e["in_mill"]
            ax2.semilogx(m["sieves_mm"], m["passing_percent"], "o:", ms=3, mfc="white", color=line.get_color(),
                         label=f"{e['rpm']:g} rpm, in mill ({m.get('lumps', '?')} "
                               f"lump{'' if m.get('lumps') == 1 else 's'})")
    ax2.axhline(80, color="k", ls=":", lw=0.8)
    ax2.set_xlabel("size [mm]")
    ax2.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax2.xaxis.set_minor_formatter(FuncFormatter(lambda x, _: f"{x:g}" if str(x)[0] in "25" else ""))
    ax2.set_ylabel("cumulative mass % passing")
    ax2.set_ylim(0, 102)
    ax2.set_title("Product size distribution")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    path = os.path.join(a.out, "product_vs_rpm.png")
    fig.savefig(path + ".tmp", dpi=110, format="png")
    plt.close(fig)
    os.replace(path + ".tmp", path)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
