#!/usr/bin/python3
"""Flow study table: one row per run folder of bench/flow/study/run.sh.

Usage: summarize.py runs/flow_study_*     prints two Markdown tables (flow; impacts)
and the spread (max - min over mean) of each column over the runs given.
"""
import json
import pathlib
import sys


def load(p: pathlib.Path):
    return json.loads(p.read_text()) if p.exists() else {}


def row(run: pathlib.Path):
    f = load(run / "flow" / "rpm2000" / "flow_report.json")
    t = load(run / "transport" / "rpm2000" / "summary.json")
    if not f:
        return None
    res = f.get("final_initial_residuals", {})
    h = f.get("history_last_tenth", {})
    m = h.get("mass_flow_inlet_kg_s", {})
    eb = f.get("energy_balance", {})
    return {
        "run": run.name.replace("flow_study_", ""),
        "cells": f["cells"],
        "iterations": f["iterations"],
        "converged": f["converged"],
        "p/U res": f"{res.get('p', float('nan')):.1e} / "
                   f"{max(res.get(c, 0.0) for c in ('Ux', 'Uy', 'Uz')):.1e}",
        "mass flow kg/s": f["mass_flow_kg_s"]["inlet_in"],
        "last-tenth range": f"{m.get('min', float('nan')):.3f}-{m.get('max', float('nan')):.3f}",
        "backflow in/out kg/s": f"{f['backflow_kg_s']['inlet_out']:.3f} / {f['backflow_kg_s']['outlet_in']:.3f}",
        "rim gas / tip": f["rim"]["ratio_speed_to_tip_speed"],
        "torque N m": f["shaft"]["torque_Nm"],
        "power kW": f["shaft"]["power_kW"],
        "dT0 / expected K": (f"{eb['total_temperature_rise_K']:.2f} / {eb['expected_rise_from_shaft_power_K']:.2f}"
                             if eb else "-"),
        "y+ flywheel": f["y_plus"].get("flywheel", {}).get("average", float("nan")),
        "solver CPU s": f.get("solver_cpu_s_rank0", float("nan")),
        # impacts (transport, 360 lumps)
        "fw impacts / lump": t.get("flywheel_impacts_per_particle_mean", float("nan")),
        "fw speed m/s": t.get("flywheel_impact_speed_mean_m_s", float("nan")),
        "fw normal m/s": t.get("flywheel_normal_speed_mean_m_s", float("nan")),
        "fw angle deg": t.get("flywheel_angle_mean_deg", float("nan")),
        "first strike m/s": t.get("flywheel_first_strike_speed_mean_m_s", float("nan")),
        "rebound lab m/s": t.get("flywheel_rebound_speed_lab_mean_m_s", float("nan")),
        "strike->housing m/s": t.get("strike_to_housing_speed_mean_m_s", float("nan")),
        "exited": t.get("n_exited", float("nan")),
    }


def fmt(v):
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def main(runs):
    rows = [r for r in (row(pathlib.Path(p)) for p in runs) if r]
    if not rows:
        sys.exit("no flow_report.json under the folders given")
    cols = list(rows[0].keys())
    flow_cols = cols[: cols.index("fw impacts / lump")]
    imp_cols = ["run"] + cols[cols.index("fw impacts / lump"):]
    for group in (flow_cols, imp_cols):
        print("| " + " | ".join(group) + " |")
        print("|" + "---|" * len(group))
        for r in rows:
            print("| " + " | ".join(fmt(r[c]) for c in group) + " |")
        print()
    print("spread over these runs ((max - min) / mean):")
    for c in cols:
        vals = [r[c] for r in rows if isinstance(r[c], float) and r[c] == r[c]]
        if len(vals) == len(rows) and len(vals) > 1:
            mean = sum(vals) / len(vals)
            if mean:
                print(f"  {c}: {(max(vals) - min(vals)) / abs(mean):.1%} (mean {mean:.4g})")


if __name__ == "__main__":
    main(sys.argv[1:])
