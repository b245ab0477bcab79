"""A film of an outburst run: the particles coloured by their speed over the
gas pressure on the seepage mesh, one frame per snapshot, with the tunnel's
rock and the excavation face drawn in.

usage: python3 -m cases.outburst.animate RUN_DIR [--output FILE] [--fps N]
writes RUN_DIR/outburst.mp4 (H.264, through ffmpeg), or RUN_DIR/outburst.gif
(Pillow) where matplotlib finds no ffmpeg; --output picks the file and, by
its ending (.mp4 or .gif), the format. A plane run only.
"""
import argparse
import math
import os
import sys

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib import animation
from matplotlib.tri import Triangulation
import numpy as np

from ..units import value
from .report import MPA, Run, draw_rock, initial_pressure, tunnel

DPI = 100
# Inches around the model: left, right, above (title), below (axis label, colour bars).
MARGINS = (0.75, 0.35, 0.55, 1.35)
# The model's height on the frame at least [in]: a long tunnel makes a wider frame.
MIN_HEIGHT = 1.2


def speeds(path):
    """Positions (x, y) [m] and speeds [m/s] of the particles in one snapshot."""
    with h5py.File(path) as f:
        p = f["particles"]
        return p["points"][:, :2], np.linalg.norm(p["velocity"][:], axis=1)


def speed_scale(files):
    """The speed at the top of the colour bar [m/s]: over the whole run, the
    largest of the snapshots' 99th percentiles (the fastest few fragments
    would wash out the rest), rounded up to a round number."""
    top = max(np.percentile(speeds(f)[1], 99) for f in files)
    if top <= 0:
        return 1.0
    step = 10 ** math.floor(math.log10(top))
    return math.ceil(top / step) * step


def particle_spacing(scene, count):
    """The particles' spacing at t = 0 [m]: the coal's area shared among them."""
    area = sum((value(b["box_max"][0], "m") - value(b["box_min"][0], "m")) *
               (value(b["box_max"][1], "m") - value(b["box_min"][1], "m")) for b in scene["mpm"]["bodies"])
    return math.sqrt(area / count)


def frame_size(width_m, height_m):
    """Figure size [in], in whole pixels of even count (H.264 wants even
    sides), and the model's axes' width [in]."""
    left, right, above, below = MARGINS
    axes_width = max(11.0, MIN_HEIGHT * width_m / height_m)
    axes_height = axes_width * height_m / width_m
    # A quarter pixel over: the renderer truncates the figure's size in pixels.
    even = lambda inches: (2 * math.ceil(inches * DPI / 2) + 0.25) / DPI
    return (even(left + axes_width + right), even(above + axes_height + below)), axes_width


class Film:
    """The figure, drawn once, and what each frame changes on it."""

    def __init__(self, run, geometry, speed_top):
        self.run = run
        face, floor, roof, top = (geometry[k] for k in ("face", "floor", "roof", "top"))
        left, right = float(run.nodes[:, 0].min()), float(run.nodes[:, 0].max())
        (w, h), axes_width = frame_size(right - left, top)
        self.fig = plt.figure(figsize=(w, h), dpi=DPI)
        l, r, above, below = MARGINS
        ax = self.fig.add_axes([l / w, below / h, axes_width / w, (h - above - below) / h])
        ax.set_xlim(left, right)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        draw_rock(ax, left, face, floor, roof, top)
        for y, name in ((0.5 * floor, "floor rock"), (0.5 * (roof + top), "roof rock")):
            ax.text(left + 0.02 * (right - left), y, name, va="center", fontsize=8, color="0.3", zorder=4)
        # The nodal pressure, linear over each half of a quadrilateral (Gouraud shading).
        quads = run.cells
        mesh = Triangulation(run.nodes[:, 0], run.nodes[:, 1],
                             np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]))
        self.pressure = ax.tripcolor(mesh, run.pressure(0) / MPA, shading="gouraud", cmap="Blues", vmin=0,
                                     vmax=initial_pressure(run.scene) / MPA, zorder=1)
        ax.plot([face, face], [floor, roof], color="crimson", lw=1.2, ls=":", zorder=3)
        ax.annotate("the face, opened at t = 0", (face, roof), xytext=(-4, 4), textcoords="offset points",
                    ha="right", va="bottom", fontsize=8, color="crimson", zorder=4)
        # Dots about half the particles' spacing across: the gas pressure shows between them.
        points_per_m = axes_width * 72 / (right - left)
        spacing = particle_spacing(run.scene, len(speeds(run.particle_files[0])[1]))
        size = (0.55 * spacing * points_per_m) ** 2
        self.dots = ax.scatter([], [], c=[], s=size, cmap="inferno", vmin=0, vmax=speed_top, linewidths=0,
                               zorder=2)
        bar_y, bar_h, bar_w = 0.5 / h, 0.14 / h, 0.42 * axes_width / w
        for x, mappable, label in ((l / w, self.pressure, "gas pressure p [MPa]"),
                                   ((l + axes_width) / w - bar_w, self.dots, "particle speed |v| [m/s]")):
            bar = self.fig.colorbar(mappable, cax=self.fig.add_axes([x, bar_y, bar_w, bar_h]),
                                    orientation="horizontal")
            bar.set_label(label, fontsize=9)
            bar.ax.tick_params(labelsize=8)
        title = run.scene.get("scene", {}).get("title", "Coal-and-gas outburst")
        self.fig.text(l / w, 1 - 0.27 / h, f"{title}: particle speed over gas pressure", fontsize=12,
                      va="center")
        self.clock = self.fig.text((l + axes_width) / w, 1 - 0.27 / h, "", fontsize=12, ha="right", va="center",
                                   family="monospace")

    def show(self, k):
        """Snapshot k of the particles and the seepage snapshot at its time."""
        run = self.run
        x, v = speeds(run.particle_files[k])
        self.dots.set_offsets(x)
        self.dots.set_array(v)
        s = int(np.argmin(np.abs(np.asarray(run.seepage_times) - run.times[k])))
        self.pressure.set_array(run.pressure(s) / MPA)
        self.clock.set_text(f"t = {run.times[k]:.3f} s")


def film_format(path):
    """"mp4" or "gif", by the file's ending: H.264 through ffmpeg, or a GIF through Pillow."""
    ending = os.path.splitext(path)[1]
    if ending not in (".mp4", ".gif"):
        raise ValueError(f"{path}: write an .mp4 or a .gif")
    if ending == ".mp4" and not animation.writers.is_available("ffmpeg"):
        raise ValueError(f"{path}: matplotlib finds no ffmpeg (scripts/install-deps.sh installs it); "
                         "write a .gif instead")
    return ending[1:]


def write(run_dir, path, fps=None):
    """The film of the run in run_dir, to path; returns its frame count."""
    kind = film_format(path)
    run = Run(run_dir)
    if run.dimension != 2:
        raise ValueError(f"{run_dir}: a {run.dimension}D run; the film is drawn of plane runs")
    count = len(run.particle_files)
    if count == 0 or count != len(run.times):
        raise ValueError(f"{run_dir}: {count} particle snapshots, {len(run.times)} in particles.xdmf")
    # About six seconds of film whatever the run's length, at 2 to 12 frames a second.
    fps = fps or min(12, max(2, round(count / 6)))
    # yuv420p: the pixel format every player reads.
    writer = (animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
              if kind == "mp4" else animation.PillowWriter(fps=fps))
    film = Film(run, tunnel(run.scene), speed_scale(run.particle_files))
    with writer.saving(film.fig, path, dpi=DPI) as w:
        for k in range(count):
            film.show(k)
            w.grab_frame()
    plt.close(film.fig)
    return count


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", help="the output folder of an outburst run (plane)")
    ap.add_argument("--output", help="the film's file, .mp4 or .gif (default: RUN/outburst.mp4, or .gif "
                                     "where there is no ffmpeg)")
    ap.add_argument("--fps", type=int, help="frames a second (default: about six seconds of film)")
    args = ap.parse_args()
    if not os.path.isdir(args.run):
        ap.error(f"{args.run}: no such folder")
    if args.fps is not None and args.fps < 1:
        ap.error(f"--fps {args.fps}: give a positive number of frames a second")
    ending = ".mp4" if animation.writers.is_available("ffmpeg") else ".gif"
    path = args.output or os.path.join(args.run, "outburst" + ending)
    try:
        count = write(args.run, path, args.fps)
    except (ValueError, FileNotFoundError, KeyError) as e:
        sys.exit(f"cases.outburst.animate: {e}")
    print(f"cases.outburst.animate: {path}, {count} frames")


if __name__ == "__main__":
    main()
