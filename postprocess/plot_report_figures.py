#!/usr/bin/python3
"""Figures the report draws itself from other stages' outputs.

  mill_geometry.png                the STL surfaces of the flow stage (housing,
                                   flywheel, inlet, outlets) seen along the
                                   rotor axis and from the side
  flow_convergence_<rpm>.png       initial residual of every solved field per
                                   iteration (from the solver log) against the
                                   case's target, and the inlet/outlet volume
                                   flow per iteration (OpenFOAM's
                                   surfaceFieldValue output)

Usage: plot_report_figures.py --run RUN_DIR --out DIR [--target 1e-4]

Only what exists is drawn; a stage that has not run draws nothing. Exits
non-zero naming the file when an input exists but cannot be read.
"""

import argparse
import glob
import os
import re
import struct
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

SURFACE_COLOURS = {"housing": "#9aa7b4", "flywheel": "#c0392b", "inlet": "#2e86c1",
                   "outlet": "#27ae60"}


def read_stl(path):
    """Triangles of an ASCII or binary STL as an (n, 3, 3) array."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:5] == b"solid" and b"facet" in data[:1000]:
        v = [float(x) for x in re.findall(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", data) for x in x]
        tris = np.array(v, dtype=float).reshape(-1, 3, 3)
    else:
        if len(data) < 84:
            sys.exit(f"{path}: not an STL file (too short)")
        n = struct.unpack("<I", data[80:84])[0]
        if len(data) < 84 + 50 * n:
            sys.exit(f"{path}: binary STL says {n} triangles but is truncated")
        rec = np.frombuffer(data[84:84 + 50 * n], dtype=np.dtype(
            [("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")]))
        tris = rec["v"].astype(float)
    if tris.size == 0:
        sys.exit(f"{path}: no triangles")
    return tris


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path + ".tmp", dpi=110, format="png")
    plt.close(fig)
    os.replace(path + ".tmp", path)


def plot_geometry(geometry_dir, out):
    """Front (x-y, along the rotor axis z) and side (z-y) projections of the STL surfaces."""
    stls = sorted(glob.glob(os.path.join(geometry_dir, "*.stl")))
    if not stls:
        return None
    surfaces = [(os.path.splitext(os.path.basename(p))[0], read_stl(p)) for p in stls]
    fig, axes = plt.subplots(1, 2, figsize=(9, 7), gridspec_kw={"width_ratios": [3, 1.4]})
    for ax, (a, b), title, xlabel in ((axes[0], (0, 1), "along the rotor axis", "x [m]"),
                                      (axes[1], (2, 1), "side view", "z [m]")):
        # Housing first (behind), then the rest on top.
        for name, tris in sorted(surfaces, key=lambda s: s[0] != "housing"):
            key = next((k for k in SURFACE_COLOURS if name.startswith(k)), None)
            colour = SURFACE_COLOURS.get(key, "#888888")
            # Inlet and outlet are flat patches, often seen edge-on: draw their edges thick.
            port = key in ("inlet", "outlet")
            poly = PolyCollection(tris[:, :, [a, b]], facecolors=colour,
                                  edgecolors=colour if port else "none", linewidths=4 if port else 0,
                                  alpha=0.15 if name == "housing" else 0.8, label=name, zorder=3 if port else 2)
            ax.add_collection(poly)
        allv = np.concatenate([t.reshape(-1, 3) for _, t in surfaces])
        pad = 0.03 * (allv.max(axis=0) - allv.min(axis=0)).max()
        ax.set_xlim(allv[:, a].min() - pad, allv[:, a].max() + pad)
        ax.set_ylim(allv[:, b].min() - pad, allv[:, b].max() + pad)
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("y (up) [m]")
    handles = [plt.Rectangle((0, 0), 1, 1, color=SURFACE_COLOURS.get(
        next((k for k in SURFACE_COLOURS if n.startswith(k)), ""), "#888888")) for n, _ in surfaces]
    axes[0].legend(handles, [n for n, _ in surfaces], loc="upper right", fontsize=8)
    fig.suptitle("Mill geometry (STL surfaces of the flow and transport stages)")
    path = os.path.join(out, "mill_geometry.png")
    save(fig, path)
    return path


RESIDUAL = re.compile(r"Solving for (\w+), Initial residual = ([0-9.eE+-]+)")
TIME = re.compile(r"^Time = (\S+)")


def read_residuals(log):
    """{field: [(iteration, first initial residual of that iteration)]} from a solver log."""
    hist, it, seen = {}, None, set()
    with open(log, errors="replace") as f:
        for line in f:
            m = TIME.match(line)
            if m:
                try:
                    it = float(m.group(1))
                except ValueError:
                    it = None
                seen = set()
                continue
            m = RESIDUAL.search(line)
            if m and it is not None and m.group(1) not in seen:
                seen.add(m.group(1))
                hist.setdefault(m.group(1), []).append((it, float(m.group(2))))
    return hist


def read_flow_rate(dat):
    """(iterations, sum(phi)) from a surfaceFieldValue.dat, or None."""
    rows = []
    with open(dat) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            cells = line.split()
            try:
                rows.append((float(cells[0]), float(cells[1])))
            except (ValueError, IndexError):
                continue
    return np.array(rows) if rows else None


def plot_convergence(case_dir, label, target, out):
    logs = [p for p in glob.glob(os.path.join(case_dir, "log.*Foam"))
            if os.path.basename(p) not in ("log.blockMesh", "log.potentialFoam")]
    logs = [p for p in logs if "Simple" in p or "simple" in p or "Pimple" in p or "pimple" in p]
    if not logs:
        return None
    hist = read_residuals(logs[0])
    if not hist:
        return None
    flows = {}
    for name in ("inletFlow", "outletFlow"):
        files = sorted(glob.glob(os.path.join(case_dir, "postProcessing", name, "*", "surfaceFieldValue.dat")))
        if files:
            d = read_flow_rate(files[-1])
            if d is not None:
                flows[name] = d
    fig, axes = plt.subplots(1, 2 if flows else 1, figsize=(11 if flows else 7, 4.2), squeeze=False)
    ax = axes[0][0]
    for field, pts in sorted(hist.items()):
        a = np.array(pts)
        ax.semilogy(a[:, 0], a[:, 1], lw=1, label=field)
    if target > 0:
        ax.axhline(target, color="k", ls="--", lw=1, label=f"target {target:g}")
    ax.set_xlabel("iteration")
    ax.set_ylabel("initial residual")
    ax.set_title(f"{label}: residuals ({os.path.basename(logs[0])[4:]})")
    ax.legend(fontsize=7, ncol=2)
    if flows:
        ax = axes[0][1]
        for name, d in flows.items():
            ax.plot(d[:, 0], np.abs(d[:, 1]), lw=1, label=name.replace("Flow", "") + " |sum(phi)|")
        ax.set_xlabel("iteration")
        ax.set_ylabel("through-flow [m3/s] (kg/s if compressible)")
        ax.set_title(f"{label}: through-flow")
        ax.legend(fontsize=8)
    path = os.path.join(out, f"flow_convergence_{label}.png")
    save(fig, path)
    return path


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", required=True, help="run folder (runs/<case>)")
    p.add_argument("--out", required=True, help="folder for the PNGs")
    p.add_argument("--target", type=float, default=1e-4, help="residual target line")
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    written = []
    rpm_dirs = sorted(glob.glob(os.path.join(a.run, "flow", "rpm*")))
    for d in rpm_dirs:
        if os.path.isdir(os.path.join(d, "geometry")):
            written.append(plot_geometry(os.path.join(d, "geometry"), a.out))
            break
    for d in rpm_dirs:
        if os.path.isdir(os.path.join(d, "case")):
            written.append(plot_convergence(os.path.join(d, "case"), os.path.basename(d), a.target, a.out))
    for w in written:
        if w:
            print(w)
    return 0


if __name__ == "__main__":
    sys.exit(main())
