#!/usr/bin/env python3
"""The class lump at the cap against the calibration's element size
(bench/feed/cap/run.sh): per run, the 45-63 mm class's measured breakage
column (where its mass goes in one pass), the steady product's P80 and
circulating load with their bootstrap bands, and the in-mill lumps' pieces."""
import glob
import json
import os
import sys


def load(run):
    m = json.load(open(f"{run}/breakage/breakage_matrix.json"))
    c = json.load(open(f"{run}/breakage/circuit.json"))
    return m, c


def column(m, j):
    s = m["rotor_speeds"][0]
    col = s["columns"][j]
    return col, [row[j] for row in s["matrix"]]


def main():
    runs = sys.argv[1:3]
    names = [r.rstrip("/").split("/")[-1] for r in runs]
    data = [load(r) for r in runs]
    classes = data[0][0]["classes"]
    j = next(k for k, c in enumerate(data[0][0]["rotor_speeds"][0]["columns"])
             if c.get("origin") == "measured" and c.get("runs", "").startswith("the class's own"))
    print(f"class {classes[j]['name']} (its own in-mill lumps):")
    print("| | " + " | ".join(r.rstrip("/").split("/")[-1] for r in runs) + " |")
    print("|---|" + "---|" * len(runs))
    cols = [column(m, j) for m, _ in data]
    print("| lump elements | " + " | ".join(str(c["lump_elements"]) for c, _ in cols) + " |")
    print("| element size / calibration's | " +
          " | ".join(f"{c.get('element_size_vs_calibration', float('nan')):.3f}" for c, _ in cols) + " |")
    print("| lumps | " + " | ".join(str(c["lumps"]) for c, _ in cols) + " |")
    for i in range(j, len(classes)):
        vals = [b[i] for _, b in cols]
        if max(vals) < 5e-4:
            continue
        print(f"| to {classes[i]['name']} | " + " | ".join(f"{100 * v:.1f} %" for v in vals) + " |")
    below = [sum(b[i] for i in range(len(classes)) if classes[i]["upper_mm"] <= 10.0) for _, b in cols]
    print("| to the classes wholly below the 10 mm cut | " + " | ".join(f"{100 * v:.1f} %" for v in below) + " |")
    for label, key in (("product P80 mm", "p80_mm"), ("circulating load t/t", "circulating_load"),
                       ("specific energy kWh/t", "specific_energy_kWh_t")):
        cells = []
        for _, c in data:
            s = c["rotor_speeds"][0]
            v = s.get(key)
            if v is None and key == "specific_energy_kWh_t":
                v = s.get("energy", {}).get(key)
            band = s.get("band", {}).get(key)
            cells.append(f"{v:.3g}" + (f" ({band[0]:.3g}-{band[1]:.3g})" if band and None not in band else ""))
        print(f"| {label} | " + " | ".join(cells) + " |")


    # The same strikes in both runs (the transport is shared): the class's
    # in-mill jobs paired by label (rotor speed, class, stage-1 lump id),
    # the mean of each figure and the paired difference with its standard
    # error over the pairs.
    lumps = []
    for r in runs:
        jobs = {}
        for f in sorted(glob.glob(f"{r}/breakage/jobs/rpm*_c{j}_mill_p*/in_mill.json")):
            jobs[os.path.basename(os.path.dirname(f))] = json.load(open(f))
        lumps.append(jobs)
    ids = sorted(set(lumps[0]) & set(lumps[1]))
    print(f"\nper lump, {len(ids)} strikes paired (mean; paired difference {names[1]} - {names[0]} +- standard error):")
    print("| figure | " + " | ".join(names) + " | difference |")
    print("|---|---|---|---|")
    for key in ("velocity_m_s", "largest_mass_fraction", "single_mass_fraction", "t10_percent",
                "broken_bond_fraction", "n_pieces", "specific_energy_J_kg", "wall_seconds"):
        a = [float(lumps[0][i][key]) for i in ids]
        b = [float(lumps[1][i][key]) for i in ids]
        d = [y - x for x, y in zip(a, b)]
        n = len(d)
        md = sum(d) / n
        se = (sum((x - md) ** 2 for x in d) / (n - 1) / n) ** 0.5 if n > 1 else float("nan")
        print(f"| {key} | {sum(a) / n:.4g} | {sum(b) / n:.4g} | {md:+.3g} +- {se:.2g} |")


if __name__ == "__main__":
    main()
