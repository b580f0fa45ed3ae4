#!/usr/bin/python3
"""Print a flow benchmark's figures (from flow_report.json and
sample_report.json) as a Markdown table row, and plot the mid-plane speed
of field.h5 with axes and a colour bar (midplane_speed_axes.png).

Usage: summarize.py <run folder>   (e.g. runs/bench_flow_quick)
"""
import json
import pathlib
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(run: pathlib.Path) -> None:
    for rep_file in sorted((run / "flow").glob("rpm*/flow_report.json")):
        label = rep_file.parent.name
        r = json.loads(rep_file.read_text())
        m = r["mass_flow_kg_s"]
        yp = r["y_plus"]
        rim = r["rim"]
        print("| preset | model | np | cells | iterations | converged | p res | U res | "
              "in kg/s | out kg/s | imbalance | rim gas/tip speed | y+ flywheel avg (max) | "
              "y+ housing avg | mesh s | solve s |")
        res = r["final_initial_residuals"]
        u_res = max(res.get(c, 0.0) for c in ("Ux", "Uy", "Uz"))
        print(f"| {r['mesh_preset']} | {r['gas_model']} | {r['np']} | {r['cells']} | {r['iterations']} | "
              f"{r['converged']} | {res.get('p', float('nan')):.2g} | {u_res:.2g} | "
              f"{m['inlet_in']:.4g} | {m['outlet_out']:.4g} | {100 * m['imbalance_relative']:.3f}% | "
              f"{rim.get('gas_speed_mean_m_s', 0):.1f}/{rim.get('tip_speed_m_s', 0):.1f} m/s | "
              f"{yp['flywheel']['average']:.0f} ({yp['flywheel']['max']:.0f}) | {yp['housing']['average']:.0f} | "
              f"{r['wall_time_s']['mesh']:.0f} | {r['wall_time_s']['solve']:.0f} |")
        if r.get("mirrored"):
            h = r["solved_half"]["mass_flow_kg_s"]
            print(f"domain: half z >= 0 (symmetry plane z = 0), mirrored: cells are the half's; "
                  f"mass flows 2 x the half's {h['inlet_in']:.4g} / {h['outlet_out']:.4g} kg/s; "
                  f"solver CPU rank 0 {r.get('solver_cpu_s_rank0', 0):.1f} s")
        field = run / "sample" / label / "field.h5"
        if not field.exists():
            continue
        with h5py.File(field, "r") as f:
            U = f["U"][:]
            mask = f["mask"][:]
            origin, spacing, dims = f.attrs["origin"], f.attrs["spacing"], f.attrs["dims"]
        k = int(round((0.0 - origin[2]) / spacing[2]))
        speed = np.linalg.norm(U[k], axis=-1)
        speed = np.ma.masked_where(mask[k] == 0, speed)
        x = origin[0] + spacing[0] * np.arange(dims[0])
        y = origin[1] + spacing[1] * np.arange(dims[1])
        fig, ax = plt.subplots(figsize=(4.2, 8))
        pc = ax.pcolormesh(x, y, speed, shading="gouraud", cmap="viridis")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(f"|U| on z = 0, {r['rpm']:g} rpm ({r['mesh_preset']})\nMRF frozen rotor", fontsize=9)
        fig.colorbar(pc, ax=ax, label="|U| [m/s]", shrink=0.8)
        out = run / "sample" / label / "midplane_speed_axes.png"
        fig.savefig(out, dpi=110, bbox_inches="tight")
        print(f"picture: {out}")


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1]))
