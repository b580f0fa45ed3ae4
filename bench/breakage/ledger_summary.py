#!/usr/bin/env python3
"""Per-speed figures of a breakage sweep's energy ledgers (bench/README.md, "Energy ledger").

    /usr/bin/python3 bench/breakage/ledger_summary.py RUN_FOLDER

Reads every impact's result.json under RUN_FOLDER/breakage/jobs/ and prints,
per impact speed (mean, min-max over repeats): pieces, largest piece %, the
ledger's residual (% of the energy put in, the largest over the run), the
fastest element over the impact speed, the largest overlap on the surface
over the element radius, the comminution efficiency (% of the impact energy
released by breaking bonds), and the wall seconds per impact.
"""
import json
import pathlib
import sys
from collections import defaultdict


def main(run):
    jobs = sorted((pathlib.Path(run) / "breakage" / "jobs").glob("*/result.json"))
    by_v = defaultdict(list)
    for f in jobs:
        r = json.loads(f.read_text())
        if "energy" not in r:
            continue
        by_v[r["velocity_m_s"]].append(r)
    print("| V [m/s] | runs | pieces | largest piece % (min-max) | max residual % of input | fastest element / V |"
          " wall overlap / r | efficiency % | wall s per impact |")
    print("|---|---|---|---|---|---|---|---|---|")
    for v in sorted(by_v):
        rs = by_v[v]
        lg = [100 * r["largest_mass_fraction"] for r in rs]
        res = [100 * abs(r["energy"]["residual_fraction_max"]) for r in rs]
        sp = [r["energy"]["max_element_speed_m_s"] / v for r in rs]
        ov = [r["energy"]["wall_overlap_max"] for r in rs]
        ef = [100 * r["energy"]["comminution_efficiency"] for r in rs]
        ws = [r["wall_seconds"] for r in rs]
        mean = lambda a: sum(a) / len(a)
        print(f"| {v:g} | {len(rs)} | {mean([r['n_pieces'] for r in rs]):.0f} | {mean(lg):.1f} ({min(lg):.1f}-{max(lg):.1f}) |"
              f" {max(res):.3f} | {max(sp):.2f} | {max(ov):.2f} | {mean(ef):.1f} | {mean(ws):.0f} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "runs/reference")
