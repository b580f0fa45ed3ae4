#!/usr/bin/env python3
"""Table of bench/breakage/adaptive_step.sh (bench/README.md, "Adaptive time step").

    /usr/bin/python3 bench/breakage/adaptive_summary.py OUT

Per run of OUT/{fixed,adaptive}/breakage/jobs/*: steps (the log's Loop
lines), liggghts-mill CPU seconds (OUT/MODE.times), the first and last step
(steps.csv of the adaptive runs), pieces, largest piece %, broken bonds %,
the ledger's residual; then per speed and mode the mean and min-max.
"""
import csv
import json
import pathlib
import re
import sys
from collections import defaultdict


def steps_of(log):
    n = 0
    for line in log.read_text().splitlines():
        m = re.match(r"Loop time of \S+ on \d+ procs for (\d+) steps", line)
        if m:
            n += int(m.group(1))
    return n


def main(out):
    out = pathlib.Path(out)
    rows = []
    for mode in ("fixed", "adaptive"):
        cpu = {}
        tf = out / f"{mode}.times"
        if tf.exists():
            for line in tf.read_text().splitlines():
                parts = line.split()
                if len(parts) == 3:
                    cpu[pathlib.Path(parts[0]).parent.name] = float(parts[1]) + float(parts[2])
        for res in sorted((out / mode / "breakage" / "jobs").glob("*/result.json")):
            job = res.parent
            r = json.loads(res.read_text())
            dt = ""
            sf = job / "run" / "steps.csv"
            if sf.exists():
                st = [x for x in csv.DictReader(l for l in sf.read_text().splitlines() if not l.startswith("#"))]
                if st:
                    dt = f"{float(st[0]['dt_s']):.3g} -> {max(float(x['dt_s']) for x in st):.3g}"
            rows.append(dict(mode=mode, job=job.name, v=r["velocity_m_s"], rep=r.get("repeat", 0),
                             steps=steps_of(job / "run" / "liggghts.log"), cpu=cpu.get(job.name, float("nan")),
                             dt=dt, pieces=r["n_pieces"], largest=100 * r["largest_mass_fraction"],
                             broken=100 * r["broken_bond_fraction"],
                             residual=r.get("energy", {}).get("residual_fraction", float("nan"))))
    print("| mode | job | steps | CPU s | step s (first -> largest) | pieces | largest % | broken bonds % | residual / input |")
    print("|---|---|---|---|---|---|---|---|---|")
    for x in rows:
        print(f"| {x['mode']} | {x['job']} | {x['steps']} | {x['cpu']:.1f} | {x['dt']} | {x['pieces']} | "
              f"{x['largest']:.1f} | {x['broken']:.1f} | {x['residual']:.1e} |")
    print()
    by = defaultdict(list)
    for x in rows:
        by[(x["v"], x["mode"])].append(x)
    print("| V [m/s] | mode | runs | steps (mean) | CPU s (mean, min-max) | pieces (mean, min-max) | largest % (mean, min-max) | broken bonds % (mean, min-max) |")
    print("|---|---|---|---|---|---|---|---|")

    def mm(xs, f="{:.1f}"):
        return f"{f.format(sum(xs) / len(xs))} ({f.format(min(xs))}-{f.format(max(xs))})"

    for (v, mode) in sorted(by, key=lambda k: (k[0], k[1] != "fixed")):
        xs = by[(v, mode)]
        print(f"| {v:g} | {mode} | {len(xs)} | {sum(x['steps'] for x in xs) / len(xs):.0f} | "
              f"{mm([x['cpu'] for x in xs])} | {mm([x['pieces'] for x in xs], '{:.0f}')} | "
              f"{mm([x['largest'] for x in xs])} | {mm([x['broken'] for x in xs])} |")


if __name__ == "__main__":
    main(sys.argv[1])
