#!/usr/bin/python3
"""One in-mill lump struck and flung into the housing, as a short animation.

Reads the run's frame dump (a LIGGGHTS `dump custom` text file of every
snapshot: id type radius x y z f_bonds v_frame_time, written by
liggghts_inputs/in_mill.in.tmpl when frame_interval > 0) and the mill's
housing and flywheel STL files (the flywheel at its angle at t = 0), and
draws each snapshot offscreen (matplotlib Agg) in the plane of the rotor:
the housing and the flywheel cut at z = 0 (the flywheel turned by omega t
about the rotor axis), the elements as discs of their own radius coloured by
their intact bond count, the time in ms in a corner. The view is the housing's
width over the heights the lump and the rotor reach.

Writes into --out:
  animation.gif         every frame (GIF, looped)
  animation_first.png, animation_middle.png, animation_last.png
                        the first, middle and last frame as stills
  animation.json        what was drawn: frames, times, the element centroid of
                        the first and last frame, the mean pixel difference of
                        the first and last frame, the caption
  animation.md          the animation and the stills with their captions, for
                        Markdown pages

Usage: plot_animation.py --frames run/frames.dump --housing run/stl/housing.stl
                         --flywheel run/stl/flywheel.stl --axis 0,1.2 --omega 209.44
                         --caption "lump 3 at 2000 rpm" --out animation
Exits with a message naming the file (and line) on a missing or broken input.
"""

import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection, LineCollection, PolyCollection  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402
from PIL import Image  # noqa: E402

COLUMNS = ("id", "radius", "x", "y", "z", "f_bonds", "v_frame_time")
WIDTH_PX, HEIGHT_PX, DPI = 720, 400, 80  # frame size; the GIF stays well under 5 MB


class FrameError(Exception):
    """A frame dump that cannot be read; the message names the file and line."""


def read_frames(path):
    """Every snapshot of a `dump custom` text file, in order.

    Returns a list of dicts: step, time_s, and arrays id, radius, x, y, z,
    bonds (one entry per element, sorted by id). Raises FrameError naming the
    file (and line) when it is missing, empty, truncated or lacks a column.
    """
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise FrameError(f"{path}: cannot read the frame dump ({e.strerror})") from None
    frames = []
    i, n = 0, len(lines)

    def expect(item, at):
        if at >= n or not lines[at].startswith("ITEM: " + item):
            got = lines[at] if at < n else "the end of the file"
            raise FrameError(f"{path}:{at + 1}: expected 'ITEM: {item}', got '{got}' (a truncated or foreign dump?)")

    while i < n:
        if not lines[i].strip():
            i += 1
            continue
        expect("TIMESTEP", i)
        try:
            step = int(lines[i + 1])
            expect("NUMBER OF ATOMS", i + 2)
            count = int(lines[i + 3])
        except (IndexError, ValueError):
            raise FrameError(f"{path}:{i + 2}: expected the step and the atom count of a snapshot") from None
        expect("BOX BOUNDS", i + 4)
        expect("ATOMS", i + 8)
        names = lines[i + 8].split()[2:]
        missing = [c for c in COLUMNS if c not in names]
        if missing:
            raise FrameError(f"{path}:{i + 9}: missing column(s) {', '.join(missing)} (got {' '.join(names)})")
        first = i + 9
        rows = lines[first:first + count]
        if len(rows) < count:
            raise FrameError(f"{path}: the snapshot of step {step} has {len(rows)} of {count} element lines "
                             "(a truncated dump: the run was cut short?)")
        try:
            data = np.array([[float(v) for v in r.split()] for r in rows], dtype=float).reshape(count, len(names))
        except ValueError:
            raise FrameError(f"{path}:{first + 1}-{first + count}: the snapshot of step {step} has a line that "
                             f"is not {len(names)} numbers") from None
        col = {c: data[:, names.index(c)] for c in COLUMNS}
        order = np.argsort(col["id"], kind="stable")
        frame = {c: col[c][order] for c in ("id", "radius", "x", "y", "z")}
        frame["bonds"] = col["f_bonds"][order]
        frame["step"] = step
        frame["time_s"] = float(col["v_frame_time"][0]) if count else float("nan")
        frames.append(frame)
        i = first + count
    if not frames:
        raise FrameError(f"{path}: no snapshot in the frame dump (did the run write frames? frame_interval > 0)")
    ids = frames[0]["id"]
    for f in frames[1:]:
        if len(f["id"]) != len(ids) or np.any(f["id"] != ids):
            raise FrameError(f"{path}: the snapshot of step {f['step']} holds other elements than the first "
                             f"({len(f['id'])} against {len(ids)}): elements were lost")
    return frames


def read_stl(path):
    """The triangles of an ASCII STL file as an (n, 3, 3) array."""
    try:
        with open(path) as f:
            vs = [[float(v) for v in line.split()[1:4]] for line in f if line.strip().startswith("vertex")]
    except OSError as e:
        raise FrameError(f"{path}: cannot read the STL ({e.strerror})") from None
    except ValueError:
        raise FrameError(f"{path}: a vertex line that is not three numbers") from None
    if not vs or len(vs) % 3:
        raise FrameError(f"{path}: {len(vs)} vertices, expected a positive multiple of 3 (an ASCII STL)")
    return np.array(vs).reshape(-1, 3, 3)


def cut(tris, z):
    """Segments (n, 2, 2) where the plane at height z along the axis cuts the triangles."""
    segs = []
    for t in tris:
        d = t[:, 2] - z
        pts = []
        for a, b in ((0, 1), (1, 2), (2, 0)):
            if (d[a] < 0) != (d[b] < 0):
                s = d[a] / (d[a] - d[b])
                pts.append(t[a, :2] + s * (t[b, :2] - t[a, :2]))
        if len(pts) == 2:
            segs.append(pts)
    return np.array(segs).reshape(-1, 2, 2)


def faces(tris):
    """The faces of a prism along z seen from +z: its triangles facing +z, projected."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    n = np.cross(e1, e2)
    up = n[:, 2] > 0.5 * np.linalg.norm(n, axis=1)
    return tris[up][:, :, :2]


def turn(xy, axis, angle):
    """Points (..., 2) turned by angle (rad, counter-clockwise) about axis."""
    c, s = math.cos(angle), math.sin(angle)
    p = xy - axis
    return np.stack([axis[0] + c * p[..., 0] - s * p[..., 1], axis[1] + s * p[..., 0] + c * p[..., 1]], axis=-1)


def view(frames, housing, axis, tip):
    """The mill window (x0, x1, y0, y1): the housing's width over the heights the lump and rotor reach."""
    hx = housing[:, :, 0]
    hy = housing[:, :, 1]
    x0, x1 = float(hx.min()), float(hx.max())
    ys = np.concatenate([f["y"] for f in frames])
    y0 = min(float(np.percentile(ys, 1)), axis[1] - tip)
    y1 = max(float(np.percentile(ys, 99)), axis[1] + tip)
    margin = 0.04 * (x1 - x0)
    y0 = max(y0 - margin, float(hy.min()) - margin)
    y1 = min(y1 + margin, float(hy.max()) + margin)
    return x0 - margin, x1 + margin, y0, y1


class Panel:
    """One axes of a frame: the housing, the turning flywheel and the elements."""

    def __init__(self, ax, housing_segs, flywheel_faces, flywheel_segs, first, bmax, wall_width):
        self.ax = ax
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.add_collection(LineCollection(housing_segs, colors="0.2", linewidths=wall_width))
        self.faces, self.segs = flywheel_faces, flywheel_segs
        self.wheel = PolyCollection(flywheel_faces, facecolors="0.78", edgecolors="0.78", linewidths=0.3)
        self.wheel_edge = LineCollection(flywheel_segs, colors="0.35", linewidths=0.8)
        ax.add_collection(self.wheel)
        ax.add_collection(self.wheel_edge)
        d = 2 * first["radius"]
        self.discs = EllipseCollection(d, d, np.zeros(len(d)), units="xy",
                                       offsets=np.column_stack([first["x"], first["y"]]),
                                       offset_transform=ax.transData, cmap="viridis",
                                       norm=plt.Normalize(0, bmax), edgecolors="none")
        ax.add_collection(self.discs)
        # Elements far smaller than a pixel still show: a dot on each disc.
        self.dots = ax.scatter(first["x"], first["y"], s=1.5, c=first["bonds"], cmap="viridis", vmin=0,
                               vmax=bmax, linewidths=0)

    def update(self, f, axis, angle):
        self.wheel.set_verts(turn(self.faces, axis, angle))
        self.wheel_edge.set_segments(turn(self.segs, axis, angle))
        xy = np.column_stack([f["x"], f["y"]])
        for c in (self.discs, self.dots):
            c.set_offsets(xy)
            c.set_array(f["bonds"])


def draw(frames, housing_segs, flywheel_faces, flywheel_segs, axis, omega, caption):
    """Renders every frame (the mill, and beside it a close view that follows the
    lump's median element); returns the frames as RGB arrays."""
    tip = float(np.max(np.hypot(*(flywheel_segs.reshape(-1, 2) - axis).T)))
    x0, x1, y0, y1 = view(frames, housing_segs, axis, tip)
    first = frames[0]
    centre = np.array([np.mean(first["x"]), np.mean(first["y"])])
    size = float(np.max(np.hypot(first["x"] - centre[0], first["y"] - centre[1]) + first["radius"]))
    half = 3.0 * size  # the close view: 6 lump radii across
    fig = plt.figure(figsize=(WIDTH_PX / DPI, HEIGHT_PX / DPI), dpi=DPI)
    fig.text(0.5, 0.99, caption, ha="center", va="top", fontsize=9)
    mill_ax = fig.add_axes([0.01, 0.01, 0.54, 0.92])
    close_ax = fig.add_axes([0.57, 0.01, 0.42, 0.92])
    bmax = max(1.0, float(first["bonds"].max()))
    mill = Panel(mill_ax, housing_segs, flywheel_faces, flywheel_segs, first, bmax, 1.5)
    close = Panel(close_ax, housing_segs, flywheel_faces, flywheel_segs, first, bmax, 3.0)
    mill_ax.set_xlim(x0, x1)
    mill_ax.set_ylim(y0, y1)
    frame_box = Rectangle((0, 0), 2 * half, 2 * half, fill=False, edgecolor="tab:red", linewidth=0.8)
    mill_ax.add_patch(frame_box)
    for spine in close_ax.spines.values():
        spine.set_edgecolor("tab:red")
    cax = close_ax.inset_axes([0.05, 0.05, 0.04, 0.3])
    cbar = fig.colorbar(close.discs, cax=cax)
    cbar.ax.tick_params(labelsize=7)
    cax.set_title("intact\nbonds", fontsize=7, loc="left")
    clock = mill_ax.text(0.03, 0.97, "", transform=mill_ax.transAxes, ha="left", va="top", fontsize=10,
                         family="monospace", bbox={"facecolor": "white", "edgecolor": "0.6", "alpha": 0.85})
    scale = close_ax.text(0.97, 0.03, f"{1e3 * 2 * half:.0f} mm across", transform=close_ax.transAxes,
                          ha="right", va="bottom", fontsize=7, color="0.3")
    del scale
    images = []
    for f in frames:
        angle = omega * f["time_s"]
        mill.update(f, axis, angle)
        close.update(f, axis, angle)
        c = np.array([np.median(f["x"]), np.median(f["y"])])
        close_ax.set_xlim(c[0] - half, c[0] + half)
        close_ax.set_ylim(c[1] - half, c[1] + half)
        frame_box.set_xy((c[0] - half, c[1] - half))
        clock.set_text(f"t = {1e3 * f['time_s']:6.2f} ms")
        fig.canvas.draw()
        images.append(np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy())
    plt.close(fig)
    return images


def write_outputs(frames, images, caption, out):
    """animation.gif, the three stills and animation.json (each via .tmp and a rename)."""
    os.makedirs(out, exist_ok=True)
    times = [f["time_s"] for f in frames]
    step_ms = 1e3 * (times[-1] - times[0]) / max(1, len(times) - 1)
    pal = Image.fromarray(images[-1]).quantize(colors=128, method=Image.Quantize.MEDIANCUT)
    gif = [Image.fromarray(im).quantize(palette=pal, dither=Image.Dither.NONE) for im in images]
    tmp = os.path.join(out, "animation.gif.tmp")
    # 100 ms per frame; the last frame held for a second before the loop restarts.
    durations = [100] * (len(gif) - 1) + [1000]
    gif[0].save(tmp, format="GIF", save_all=True, append_images=gif[1:], duration=durations, loop=0,
                optimize=False)
    os.replace(tmp, os.path.join(out, "animation.gif"))
    stills = {"first": 0, "middle": len(images) // 2, "last": len(images) - 1}
    for name, k in stills.items():
        tmp = os.path.join(out, f"animation_{name}.png.tmp")
        Image.fromarray(images[k]).save(tmp, format="PNG")
        os.replace(tmp, os.path.join(out, f"animation_{name}.png"))
    a, b = frames[0], frames[-1]
    diff = float(np.mean(np.abs(images[0].astype(float) - images[-1].astype(float))))
    info = {
        "caption": caption,
        "frames": len(frames),
        "time_first_ms": 1e3 * times[0],
        "time_last_ms": 1e3 * times[-1],
        "frame_interval_ms": step_ms,
        "elements": int(len(a["id"])),
        "centroid_first_m": [float(np.mean(a[c])) for c in ("x", "y", "z")],
        "centroid_last_m": [float(np.mean(b[c])) for c in ("x", "y", "z")],
        "intact_bonds_first": float(np.sum(a["bonds"]) / 2),
        "intact_bonds_last": float(np.sum(b["bonds"]) / 2),
        "first_last_pixel_difference": diff,
        "image_px": [int(images[0].shape[1]), int(images[0].shape[0])],
        "stills": {name: {"file": f"animation_{name}.png", "frame": k, "time_ms": 1e3 * times[k]}
                   for name, k in stills.items()},
        "gif_bytes": os.path.getsize(os.path.join(out, "animation.gif")),
        "definitions": {
            "colour": "intact bonds of each element (bond/breakable's per-element count)",
            "view": "the plane of the rotor (z = 0): housing and flywheel cut there, elements projected onto it",
            "first_last_pixel_difference": "mean absolute difference of the first and last frame, RGB 0-255",
        },
    }
    write_markdown(info, out)
    tmp = os.path.join(out, "animation.json.tmp")
    with open(tmp, "w") as f:
        json.dump(info, f, indent=2)
        f.write("\n")
    os.replace(tmp, os.path.join(out, "animation.json"))
    return info


def write_markdown(info, out):
    """animation.md: the animation and its three stills with their captions, for Markdown pages."""
    lines = [f"![{info['caption']}](animation.gif)", "",
             f"*{info['caption']}. {info['frames']} frames from t = {info['time_first_ms']:.2f} to "
             f"{info['time_last_ms']:.2f} ms, one every {info['frame_interval_ms']:.2f} ms; the elements coloured "
             "by their intact bonds, the housing and the flywheel cut in the plane of the rotor.*", "",
             "| first | middle | last |", "|---|---|---|",
             "| " + " | ".join(f"![{n} frame]({s['file']})" for n, s in info["stills"].items()) + " |",
             "| " + " | ".join(f"t = {s['time_ms']:.2f} ms" for s in info["stills"].values()) + " |", ""]
    tmp = os.path.join(out, "animation.md.tmp")
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, os.path.join(out, "animation.md"))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--frames", required=True, help="the run's frame dump (dump custom, every snapshot)")
    p.add_argument("--housing", required=True, help="housing STL (ASCII)")
    p.add_argument("--flywheel", required=True, help="flywheel STL (ASCII) at its angle at t = 0")
    p.add_argument("--axis", required=True, help="rotor axis x,y in m")
    p.add_argument("--omega", type=float, required=True, help="rotor speed, rad/s, counter-clockwise about +z")
    p.add_argument("--caption", default="", help="the line above the picture")
    p.add_argument("--out", required=True, help="output folder")
    args = p.parse_args()
    try:
        axis = np.array([float(v) for v in args.axis.split(",")])
        if axis.shape != (2,):
            raise ValueError
    except ValueError:
        sys.exit(f"--axis: expected x,y in m, got '{args.axis}'")
    try:
        frames = read_frames(args.frames)
        housing = read_stl(args.housing)
        flywheel = read_stl(args.flywheel)
    except FrameError as e:
        sys.exit(str(e))
    if len(frames) < 2:
        sys.exit(f"{args.frames}: {len(frames)} snapshot; an animation needs at least two")
    z = 1e-4 * float(np.ptp(housing[:, :, 2]))  # just off the mid-plane: no vertex on it
    housing_segs = cut(housing, z)
    flywheel_segs = cut(flywheel, z)
    if not len(housing_segs) or not len(flywheel_segs):
        sys.exit(f"{args.housing}, {args.flywheel}: the plane z = 0 does not cut the housing and the flywheel")
    images = draw(frames, housing_segs, faces(flywheel), flywheel_segs, axis, args.omega, args.caption)
    info = write_outputs(frames, images, args.caption, args.out)
    print(f"plot_animation: {info['frames']} frames, {info['time_first_ms']:.2f}-{info['time_last_ms']:.2f} ms, "
          f"{info['gif_bytes'] / 1e6:.2f} MB -> {os.path.join(args.out, 'animation.gif')}")


if __name__ == "__main__":
    main()
