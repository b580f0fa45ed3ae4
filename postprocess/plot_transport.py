#!/usr/bin/python3
"""Plots of the transport stage, from transport.h5 only (never the raw logs).

trajectories.png            paths of up to 40 lumps (first 0.3 s each) over the mill outline, coloured by speed
flywheel_impact_speed.png   histogram of impact speed relative to the beater surface
flywheel_normal_speed.png   histogram of its normal part
flywheel_angle.png          histogram of the impact angle (90 deg = normal)
collisions_per_particle.png histogram of impacts per lump (flywheel, all surfaces)
flywheel_first_strike_speed.png  first strike of each lump against later strikes (relative speed)
flywheel_rebound_speed_lab.png   lab speed of the lumps leaving the beaters (contact ends)
strike_to_housing_speed.png      lab speed at the next housing impact after a strike
strike_to_housing_angle.png      its angle to the wall
strike_to_housing_flight_time.png  time from leaving the beater to that housing impact
impacts_per_part.png        impacts (not sliding) per struck part, and sliding contacts

Sliding contacts (normal speed below transport.sliding_threshold) are left
out of every impact histogram.

Usage: plot_transport.py --h5 transport/rpm2000/transport.h5 --out transport/rpm2000/plots
"""
import argparse
import math
import os

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402


def mill_outline(ax, geo):
    """Draws housing, inlet, outlet, hub and tip circles (section z = 0)."""
    w, h = geo["housing_width"], geo["housing_height"]
    ax.plot([-w / 2, w / 2, w / 2, -w / 2, -w / 2], [0, 0, h, h, 0], color="0.3", lw=1.2)
    for key, y, col in (("inlet", h, "tab:green"), ("outlet", 0.0, "tab:red")):
        x0, s = geo[key + "_x"], geo[key + "_size"]
        ax.plot([x0 - s / 2, x0 + s / 2], [y, y], color=col, lw=4, solid_capstyle="butt", label=key)
    cx, cy = geo["axis_x"], geo["axis_y"]
    t = np.linspace(0, 2 * math.pi, 200)
    ax.plot(cx + geo["tip_radius"] * np.cos(t), cy + geo["tip_radius"] * np.sin(t), "--", color="0.4", lw=0.8,
            label="beater tips")
    ax.fill(cx + geo["hub_radius"] * np.cos(t), cy + geo["hub_radius"] * np.sin(t), color="0.75")
    n = int(geo.get("n_plates", 0))
    for k in range(n):
        a = 2 * math.pi * k / max(n, 1)
        ax.plot([cx + geo["hub_radius"] * math.cos(a), cx + geo["tip_radius"] * math.cos(a)],
                [cy + geo["hub_radius"] * math.sin(a), cy + geo["tip_radius"] * math.sin(a)], color="0.5", lw=2)


def trajectories(f, geo, out, max_lumps=40, span=0.3):
    """Paths of up to max_lumps lumps (evenly chosen ids), each over its first
    `span` seconds, coloured by lab-frame speed (scale clipped at the 99th
    percentile of all samples)."""
    tr = f["trajectories"]
    ids = tr["particle_id"][...]
    pos = tr["position"][...].reshape(-1, 3) if len(ids) else np.zeros((0, 3))
    speed = tr["speed"][...]
    t = tr["time"][...]
    fig, ax = plt.subplots(figsize=(5.5, 9))
    mill_outline(ax, geo)
    all_ids = np.unique(ids)
    chosen = all_ids[np.linspace(0, len(all_ids) - 1, min(max_lumps, len(all_ids))).astype(int)] if len(all_ids) else []
    segs, cols = [], []
    gap = 1.5 * np.diff(np.unique(t)).min() if len(np.unique(t)) > 1 else 0.0
    for pid in chosen:
        m = ids == pid
        p, s, tt = pos[m], speed[m], t[m]
        order = np.argsort(tt)
        p, s, tt = p[order], s[order], tt[order]
        keep = tt <= tt[0] + span
        p, s, tt = p[keep], s[keep], tt[keep]
        for i in range(len(p) - 1):
            if gap and tt[i + 1] - tt[i] > gap:
                continue
            segs.append([(p[i, 0], p[i, 1]), (p[i + 1, 0], p[i + 1, 1])])
            cols.append(0.5 * (s[i] + s[i + 1]))
    if segs:
        vmax = float(np.percentile(speed, 99)) if len(speed) else 1.0
        lc = LineCollection(segs, array=np.asarray(cols), cmap="viridis", linewidths=0.9)
        lc.set_clim(0.0, vmax)
        ax.add_collection(lc)
        fig.colorbar(lc, ax=ax, label="lump speed (m/s), clipped at the 99th percentile", shrink=0.6)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("%d of %d lumps, first %.2g s each, %g rpm\n(flywheel drawn at t = 0; x-y projection)"
                 % (len(chosen), len(all_ids), span, f.attrs["rpm"]), fontsize=10)
    ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "trajectories.png"), dpi=130)
    plt.close(fig)


def finish(fig, ax, xlabel, title, path):
    """Labels a histogram's axes and title and saves it."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel("count")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def histogram(values, xlabel, title, path, bins=30, discrete=False):
    """One histogram PNG; says so when there is nothing to plot."""
    fig, ax = plt.subplots(figsize=(6, 4))
    if len(values):
        if discrete:
            hi = int(max(values))
            ax.hist(values, bins=np.arange(-0.5, hi + 1.5, 1.0), color="tab:blue", edgecolor="k")
        else:
            ax.hist(values, bins=bins, color="tab:blue", edgecolor="k")
        ax.axvline(np.mean(values), color="tab:red", lw=1.5, label="mean %.3g" % np.mean(values))
        ax.legend()
    else:
        ax.text(0.5, 0.5, "no impacts", ha="center", va="center", transform=ax.transAxes)
    finish(fig, ax, xlabel, title, path)


def overlaid(groups, xlabel, title, path, bins=30):
    """Histograms of several labelled lists on common bins (label, values, colour)."""
    fig, ax = plt.subplots(figsize=(6, 4))
    allv = np.concatenate([np.asarray(v, dtype=float) for _, v, _ in groups]) if groups else np.zeros(0)
    if len(allv):
        edges = np.histogram_bin_edges(allv, bins=bins)
        for label, v, col in groups:
            if len(v):
                ax.hist(v, bins=edges, color=col, alpha=0.6, edgecolor="k",
                        label="%s: %d, mean %.3g" % (label, len(v), np.mean(v)))
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no strikes", ha="center", va="center", transform=ax.transAxes)
    finish(fig, ax, xlabel, title, path)


def finite(a):
    a = np.asarray(a, dtype=float)
    return a[np.isfinite(a)]


def strikes(f, rpm, out):
    """The beater strikes (/strikes) and the housing impacts after them."""
    if "strikes" not in f:
        return
    s = f["strikes"]
    first = s["first"][...] == 1
    speed = s["impact_speed"][...]
    overlaid([("first strike of a lump", speed[first], "tab:orange"), ("later strikes", speed[~first], "tab:blue")],
             "impact speed relative to the beater (m/s)",
             "Beater strikes at %g rpm: first strike of each lump and later ones" % rpm,
             os.path.join(out, "flywheel_first_strike_speed.png"))
    histogram(finite(s["rebound_speed_lab"][...]), "lab speed leaving the beater (m/s)",
              "Lumps leaving the beaters at %g rpm (lab frame, at the end of the contact)" % rpm,
              os.path.join(out, "flywheel_rebound_speed_lab.png"))
    histogram(finite(s["housing_speed"][...]), "lab speed at the housing (m/s)",
              "Next housing impact after a beater strike, %g rpm" % rpm,
              os.path.join(out, "strike_to_housing_speed.png"))
    histogram(finite(s["housing_angle"][...]), "impact angle to the wall (deg, 90 = normal)",
              "Next housing impact after a strike: angle, %g rpm" % rpm,
              os.path.join(out, "strike_to_housing_angle.png"), bins=18)
    histogram(1e3 * finite(s["flight_time"][...]), "time of flight from the beater to the housing (ms)",
              "Flight from the beater to the housing, %g rpm" % rpm,
              os.path.join(out, "strike_to_housing_flight_time.png"))


def parts(f, rpm, out):
    """Impacts (not sliding) per struck part, and the sliding contacts."""
    imp = f["impacts"]
    if "part" not in imp:
        return
    codes = imp.attrs["part_codes"]
    codes = codes.decode() if isinstance(codes, bytes) else str(codes)
    names = [c.split(" = ")[1] for c in codes.split(", ")[1:]]
    part = imp["part"][...]
    sliding = imp["sliding"][...] == 1
    counts = [int(np.sum((part == k) & ~sliding)) for k in range(len(names))]
    fig, ax = plt.subplots(figsize=(7, 4))
    labels = names + ["sliding (all parts)"]
    values = counts + [int(np.sum(sliding))]
    flywheel = ("plate_face", "plate_tip", "hub", "side_cap")
    colours = ["tab:orange" if n in flywheel else "0.8" if n == "other" else "tab:blue" for n in names] + ["0.6"]
    ax.bar(range(len(values)), values, color=colours, edgecolor="k")
    for k, v in enumerate(values):
        ax.text(k, v, str(v), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(range(len(values)))
    ax.set_xticklabels(labels, rotation=35, ha="right", fontsize=8)
    ax.set_ylabel("contacts")
    ax.set_title("Impacts per struck part at %g rpm (orange: flywheel, blue: housing)" % rpm, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "impacts_per_part.png"), dpi=130)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--h5", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with h5py.File(a.h5, "r") as f:
        geo = {k: float(v) for k, v in f["geometry"].attrs.items() if k != "length_unit"}
        rpm = f.attrs["rpm"]
        imp = f["impacts"]
        fly = imp["surface"][...] == 0
        if "sliding" in imp:
            fly &= imp["sliding"][...] == 0
        trajectories(f, geo, a.out)
        tag = "flywheel at %g rpm, relative to the beater surface" % rpm
        histogram(imp["speed"][...][fly], "impact speed (m/s)", "Impact speed, " + tag,
                  os.path.join(a.out, "flywheel_impact_speed.png"))
        histogram(imp["normal_speed"][...][fly], "normal impact speed (m/s)", "Normal speed, " + tag,
                  os.path.join(a.out, "flywheel_normal_speed.png"))
        histogram(imp["angle"][...][fly], "impact angle to the surface (deg, 90 = normal)",
                  "Impact angle, flywheel at %g rpm" % rpm, os.path.join(a.out, "flywheel_angle.png"), bins=18)
        n_all = f["particles"]["n_impacts"][...]
        n_fly = f["particles"]["n_flywheel_impacts"][...]
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, n, what, col in ((axes[0], n_fly, "flywheel impacts", "tab:orange"),
                                 (axes[1], n_all, "impacts on all surfaces", "tab:blue")):
            hi = int(max(n.max() if len(n) else 0, 1))
            step = max(1, int(math.ceil((hi + 1) / 40.0)))
            ax.hist(n, bins=np.arange(-0.5, hi + step + 0.5, step), color=col, edgecolor="k")
            ax.axvline(np.mean(n) if len(n) else 0, color="tab:red", lw=1.5,
                       label="mean %.3g" % (np.mean(n) if len(n) else 0))
            ax.set_xlabel("%s per lump" % what)
            ax.set_ylabel("lumps")
            ax.legend()
        fig.suptitle("Collisions per lump at %g rpm (%d lumps)" % (rpm, len(n_all)), fontsize=11)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "collisions_per_particle.png"), dpi=130)
        plt.close(fig)
        strikes(f, rpm, a.out)
        parts(f, rpm, a.out)


if __name__ == "__main__":
    main()
