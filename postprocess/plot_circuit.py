#!/usr/bin/python3
"""The closed circuit's product against rotor speed, from breakage/circuit.json.

circuit.json (written by the breakage stage for a case with a feed) holds, per
rotor speed, the steady product of the closed circuit (the feed, the in-mill
breakage matrix and the sharp cut at feed.cut_size_mm): its cumulative %
passing each sieve (mm), P50 and P80, the circulating load and the mass-balance
residual; with feed.target_p80_mm, the decision (the lowest rotor speed that
meets the target). This draws circuit_p80_vs_rpm.png:

  left   P80 and P50 of the product [mm] against rpm (a point finer than the
         finest sieve is drawn at that sieve, hollow; a speed with no steady
         state is left out), with the 10-90 % band of the lumps' bootstrap
         as a bar where circuit.json has one ("band"), the target P80 as a
         horizontal line and the lowest speed that meets it as a vertical
         one; the decision's sentence (with its kWh/t) as the title
  right  the circulating load [t per t of fresh feed] against rpm and, on a
         second axis, the energy per tonne of fresh feed [kWh/t] where
         circuit.json has it ("energy"), with its band

Usage: plot_circuit.py --circuit breakage/circuit.json --out breakage/plots
"""

import argparse
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_breakage import read_json  # noqa: E402  (same folder: the results-JSON reader)

NEEDED = ("rpm", "steady")
STEADY = ("p50_mm", "p80_mm", "circulating_load", "passing_percent")


def read_circuit(path):
    data = read_json(path)
    if not isinstance(data, dict) or not isinstance(data.get("rotor_speeds"), list):
        sys.exit(f"{path}: expected an object with a list 'rotor_speeds'")
    if not isinstance(data.get("sieves_mm"), list) or not data["sieves_mm"]:
        sys.exit(f"{path}: expected a non-empty list 'sieves_mm'")
    for i, e in enumerate(data["rotor_speeds"]):
        missing = [k for k in NEEDED if k not in e]
        if not missing and e["steady"]:
            missing = [k for k in STEADY if k not in e]
        if missing:
            sys.exit(f"{path}: rotor_speeds[{i}] lacks {', '.join(missing)}")
    return data


def size_points(speeds, key, finest):
    """(rpm, size, resolved) of the steady speeds; unresolved at the finest sieve."""
    out = []
    for e in speeds:
        if not e["steady"]:
            continue
        v = e[key]
        out.append((e["rpm"], finest if v is None else v, v is not None))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--circuit", required=True, help="breakage/circuit.json")
    ap.add_argument("--out", required=True, help="folder for circuit_p80_vs_rpm.png")
    a = ap.parse_args()
    data = read_circuit(a.circuit)
    speeds = sorted(data["rotor_speeds"], key=lambda e: e["rpm"])
    finest = data["sieves_mm"][0]
    os.makedirs(a.out, exist_ok=True)

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, label, colour in (("p80_mm", "P80", "C0"), ("p50_mm", "P50", "C1")):
        pts = size_points(speeds, key, finest)
        if not pts:
            continue
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "-", color=colour, label=label)
        for rpm, v, resolved in pts:
            ax.plot([rpm], [v], "o", color=colour, mfc=colour if resolved else "none")
    for e in speeds:
        band = e.get("band", {}).get("p80_mm") if isinstance(e.get("band"), dict) else None
        if isinstance(band, list) and len(band) == 2 and None not in band:
            ax.plot([e["rpm"]] * 2, band, "-", color="C0", lw=4, alpha=0.35)
    decision = data.get("decision")
    if isinstance(decision, dict) and decision.get("target_p80_mm") is not None:
        ax.axhline(decision["target_p80_mm"], color="k", ls="--", lw=1,
                   label=f"target P80 {decision['target_p80_mm']:g} mm")
        if decision.get("rpm") is not None:
            ax.axvline(decision["rpm"], color="C2", ls=":", lw=1.5,
                       label=f"lowest speed {decision['rpm']:.0f} rpm")
        ax.set_title(textwrap.fill(decision.get("sentence", ""), 70), fontsize=8)
    ax.set_xlabel("rotor speed [rpm]")
    ax.set_ylabel("closed-circuit product size [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)

    steady = [e for e in speeds if e["steady"]]
    ax2.plot([e["rpm"] for e in steady], [e["circulating_load"] for e in steady], "o-", color="C3")
    ax2.set_xlabel("rotor speed [rpm]")
    ax2.set_ylabel("circulating load [t per t of fresh feed]", color="C3")
    ax2.grid(alpha=0.3)
    with_energy = [e for e in steady if isinstance(e.get("energy"), dict)
                   and e["energy"].get("specific_energy_kWh_t") is not None]
    if with_energy:
        ax3 = ax2.twinx()
        ax3.plot([e["rpm"] for e in with_energy],
                 [e["energy"]["specific_energy_kWh_t"] for e in with_energy], "s-", color="C4")
        for e in with_energy:
            band = e.get("band", {}).get("specific_energy_kWh_t") \
                if isinstance(e.get("band"), dict) else None
            if isinstance(band, list) and len(band) == 2 and None not in band:
                ax3.plot([e["rpm"]] * 2, band, "-", color="C4", lw=4, alpha=0.35)
        ax3.set_ylabel("energy [kWh per t of fresh feed]", color="C4")
    fig.suptitle(f"Closed circuit, feed {data.get('feed', {}).get('rate_t_h', '?')} t/h, "
                 f"cut {data.get('feed', {}).get('cut_size_mm', '?')} mm")
    fig.tight_layout()
    out = os.path.join(a.out, "circuit_p80_vs_rpm.png")
    fig.savefig(out + ".tmp.png", dpi=120)
    os.replace(out + ".tmp.png", out)


if __name__ == "__main__":
    main()
