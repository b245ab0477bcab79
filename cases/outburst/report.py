"""Figures and report of the outburst case, beside the paper's (section 4.2).

usage: python3 -m cases.outburst.report RESULTS_DIR [--face X] [--tunnel-floor Y] [--tunnel-roof Y] [--top Y]
writes RESULTS_DIR/fig3_pressure.png ... fig9_displacement.png and
RESULTS_DIR/report.md.

Snapshots are the paper's "steps": the run's output times, five of them picked
evenly over the run (the paper never states its time step, model-notes
section 5). Everything is read from the run's own files: particles_*.h5,
seepage_*.h5, tracers.csv, mpm_history.csv, coupling.csv, and the geometry
from the scene they record (the face support's box, the coal's top), unless
the options give it.

The measures and figures that do not depend on the plane are written for a 3D
run too (cases.outburst_3d.report reads the heading with them).
"""
import argparse
import glob
import os
import re

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection
import numpy as np

from ..run_output import scene
from ..units import value

MPA = 1e6
# The paper's figures (section 4.2) for the table.
PAPER = {"centre": 2.55, "top": 1.94, "bottom": 1.95, "farthest": 20.0}
# The tracers' order in tracers.csv (the scene's list: top, middle, bottom of the face).
TRACERS = ("top", "centre", "bottom")


def times_of(xdmf):
    with open(xdmf) as f:
        return [float(t) for t in re.findall(r'Time Value="([^"]+)"', f.read())]


def five(n):
    """Indices of five snapshots spread over n (first after t = 0 to the last)."""
    if n <= 5:
        return list(range(n))
    return sorted(set(int(round(i)) for i in np.linspace(1, n - 1, 5)))


def tunnel(s):
    """The excavation face's x, the tunnel's floor and roof and the coal's top
    [m] in an outburst scene: the face is the support removed at t = 0. In 3D
    also the heading's half-width beside its plane of symmetry z = 0 (the
    support's extent along z)."""
    support = [o for o in s["mpm"].get("obstacles", []) if o.get("support", False)]
    if len(support) != 1:
        raise ValueError(f"the scene has {len(support)} face supports (obstacles with support = true), not one")
    lo, hi = ([value(c, "m") for c in support[0][k]] for k in ("box_min", "box_max"))
    top = max(value(b["box_max"][1], "m") for b in s["mpm"]["bodies"])
    where = {"face": hi[0], "floor": lo[1], "roof": hi[1], "top": top}
    if len(hi) == 3:
        where["half_width"] = hi[2] - lo[2]
    return where


def initial_pressure(s):
    """The largest gas pressure at t = 0 [Pa], the pressure figure's scale."""
    return max(value(r["initial_pressure"], "Pa") for r in s["seepage"]["regions"])


def coal_volume(s):
    """The coal's volume at the start: its bodies' boxes [m2 per m of depth in
    a plane scene, m3 in 3D], shared among its particles alike."""
    return sum(np.prod([value(b["box_max"][i], "m") - value(b["box_min"][i], "m") for i in range(len(b["box_max"]))])
               for b in s["mpm"]["bodies"])


class Run:
    def __init__(self, d):
        self.dir = d
        self.particle_files = sorted(glob.glob(os.path.join(d, "particles_*.h5")))
        self.seepage_files = sorted(glob.glob(os.path.join(d, "seepage_0*.h5")))
        self.times = times_of(os.path.join(d, "particles.xdmf"))
        self.seepage_times = times_of(os.path.join(d, "seepage.xdmf"))
        self.scene = scene(d)
        # The scene's dimension is its grid's: a plane run's mesh nodes carry a z = 0 the measures do not want.
        self.dimension = len(self.scene["mpm"]["grid"]["size"])
        with h5py.File(os.path.join(d, "seepage_mesh.h5")) as f:
            self.nodes = f["nodes"][:, :self.dimension]
            self.cells = f["cells"][:]
        self.tracers = np.genfromtxt(os.path.join(d, "tracers.csv"), delimiter=",", names=True)
        self.history = np.genfromtxt(os.path.join(d, "mpm_history.csv"), delimiter=",", names=True)
        self.coupling = np.genfromtxt(os.path.join(d, "coupling.csv"), delimiter=",", names=True)

    def particles(self, k):
        with h5py.File(self.particle_files[k]) as f:
            p = f["particles"]
            return {name: p[name][:] for name in p.keys() if name != "connectivity"}

    def pressure(self, k):
        with h5py.File(self.seepage_files[k]) as f:
            return f["mesh/p"][:]


def panel_grid(count, title, size=(11, 2.0)):
    fig, axes = plt.subplots(count, 1, figsize=(size[0], size[1] * count + 0.6), sharex=True,
                             constrained_layout=True)
    fig.suptitle(title)
    return fig, np.atleast_1d(axes)


def draw_rock(ax, left, face, floor, roof, top):
    ax.add_patch(plt.Rectangle((left, 0), face - left, floor, color="0.75", zorder=0))
    ax.add_patch(plt.Rectangle((left, roof), face - left, top - roof, color="0.75", zorder=0))


def section(geometry):
    """What frames an x-y section of the model: its rock and its extent
    (geometry: left, face, floor, roof, top, the model's right end)."""
    def frame(ax):
        draw_rock(ax, *geometry[:5])
        ax.set_xlim(geometry[0], geometry[5])
        ax.set_ylim(0, geometry[4])
    return frame


def particle_figure(run, picks, field, label, path, frame, cmap="viridis", vmin=None, vmax=None, select=None,
                    columns=(0, 1)):
    """A field of the particles at the picked snapshots, one panel each: all of
    them, or those select(particles) keeps, on the plane of two coordinates;
    frame(ax) draws the rock and sets the extent."""
    fig, axes = panel_grid(len(picks), label)
    for ax, k in zip(axes, picks):
        p = run.particles(k)
        values = field(p)
        points = p["points"]
        if select is not None:
            keep = select(p)
            points, values = points[keep], values[keep]
        sc = ax.scatter(points[:, columns[0]], points[:, columns[1]], c=values, s=1.5, cmap=cmap, vmin=vmin,
                        vmax=vmax, linewidths=0)
        frame(ax)
        ax.set_aspect("equal")
        ax.set_title(f"t = {run.times[k]:.3g} s (snapshot {k})", fontsize=9)
        fig.colorbar(sc, ax=ax, shrink=0.9)
    axes[-1].set_xlabel("x [m]")
    fig.savefig(path, dpi=130)
    plt.close(fig)


def pressure_figure(run, picks, quads, frame, title, path):
    """Gas pressure on quadrilaterals of the seepage mesh's nodes (m x 4 node
    indices: the plane mesh's cells, or the hexahedra's faces on a plane),
    coloured by the mean of their corners."""
    fig, axes = panel_grid(len(picks), title)
    polys = run.nodes[:, :2][quads]
    for ax, k in zip(axes, picks):
        p = run.pressure(k) / MPA
        coll = PolyCollection(polys, array=p[quads].mean(axis=1), cmap="jet", edgecolors="none")
        coll.set_clim(0, initial_pressure(run.scene) / MPA)
        ax.add_collection(coll)
        frame(ax)
        ax.set_aspect("equal")
        ax.set_title(f"t = {run.seepage_times[k]:.3g} s", fontsize=9)
        fig.colorbar(coll, ax=ax, shrink=0.9)
    axes[-1].set_xlabel("x [m]")
    fig.savefig(path, dpi=130)
    plt.close(fig)


def pressure_profile_figure(run, row, face, picks, path):
    """Pressure against distance from the face on the axis's nodes (row), at
    t = 0 and the picked snapshots; the steepest drop at every snapshot,
    (t, drop [MPa/m], metres into the seam), which the figure returns."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
    gradients = []
    for k in range(len(run.seepage_files)):
        p = run.pressure(k)[row] / MPA
        distance = run.nodes[row, 0] - face
        gradients.append((run.seepage_times[k], *steepest_drop(p, distance)))
        if k in picks or k == 0:
            ax.plot(distance, p, marker=".", label=f"t = {run.seepage_times[k]:.3g} s")
    ax.set_xlabel("distance from the excavation face [m]")
    ax.set_ylabel("gas pressure p [MPa]")
    where = f"y = {run.nodes[row[0], 1]:.3g} m" + (", z = 0" if run.dimension == 3 else "")
    ax.set_title(f"Gas pressure along the tunnel axis ({where}) (Fig. 4)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return gradients


def displacement(tr):
    """How far the tracer rows' particles have moved [m]."""
    moved = np.hypot(tr["ux_m"], tr["uy_m"])
    return np.hypot(moved, tr["uz_m"]) if "uz_m" in tr.dtype.names else moved


def tracer_peaks(tr):
    """Each tracer's (peak speed [m/s], its time [s], its last displacement [m]), by TRACERS' names."""
    peak = {}
    for k, name in enumerate(TRACERS):
        sel = tr[tr["tracer"] == k]
        i = np.argmax(sel["speed_m_per_s"])
        peak[name] = (sel["speed_m_per_s"][i], sel["time_s"][i], displacement(sel)[-1])
    return peak


def tracer_figures(tr, out):
    """Figs. 8-9: the tracers' speed and displacement against time."""
    names = {0: "particle 1 (top)", 1: "particle 2 (middle)", 2: "particle 3 (bottom)"}
    for column, label, path, title in (
            ("speed_m_per_s", "speed [m/s]", "fig8_tracer_velocity.png", "Tracer speed (Fig. 8)"),
            (None, "displacement [m]", "fig9_tracer_displacement.png", "Tracer displacement (Fig. 9)")):
        fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
        for k in range(3):
            sel = tr[tr["tracer"] == k]
            ax.plot(sel["time_s"], sel[column] if column else displacement(sel), label=names[k])
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend()
        fig.savefig(out(path), dpi=130)
        plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--face", type=float, help="x of the excavation face [m] (default: the scene's)")
    ap.add_argument("--tunnel-floor", type=float, help="[m] (default: the scene's)")
    ap.add_argument("--tunnel-roof", type=float, help="[m] (default: the scene's)")
    ap.add_argument("--top", type=float, help="height of the model [m] (default: the scene's)")
    args = ap.parse_args()
    run = Run(args.results)
    given = {"face": args.face, "floor": args.tunnel_floor, "roof": args.tunnel_roof, "top": args.top}
    if None in given.values():
        try:
            given = tunnel(run.scene) | {k: v for k, v in given.items() if v is not None}
        except ValueError as e:
            ap.error(f"{e}: give --face, --tunnel-floor, --tunnel-roof and --top")
    args.face, args.tunnel_floor, args.tunnel_roof, args.top = (given[k] for k in ("face", "floor", "roof", "top"))
    face, floor, roof, top = args.face, args.tunnel_floor, args.tunnel_roof, args.top
    # The tunnel runs from the model's left edge to the face.
    left, width = float(run.nodes[:, 0].min()), float(run.nodes[:, 0].max())
    frame = section((left, face, floor, roof, top, width))
    out = lambda name: os.path.join(args.results, name)
    picks = five(len(run.particle_files))
    seep_picks = five(len(run.seepage_files))

    pressure_figure(run, seep_picks, run.cells, frame, "Gas pressure p [MPa] (Fig. 3)", out("fig3_pressure.png"))
    gradients = pressure_profile_figure(run, axis_row(run.nodes, face, 0.5 * (floor + roof)), face, seep_picks,
                                        out("fig4_pressure_profile.png"))

    # Figs. 5-7: damage, minimum principal stress, speed.
    particle_figure(run, picks, lambda p: p["damage"].ravel(), "Damage D (Fig. 5)", out("fig5_damage.png"),
                    frame, cmap="inferno_r", vmin=0, vmax=1)
    particle_figure(run, picks, lambda p: p["sigma_min"].ravel() / MPA,
                    "Minimum principal effective stress [MPa], tension positive (Fig. 6)",
                    out("fig6_min_principal_stress.png"), frame, cmap="coolwarm")
    particle_figure(run, picks, lambda p: np.linalg.norm(p["velocity"], axis=1), "Particle speed [m/s] (Fig. 7)",
                    out("fig7_velocity.png"), frame, cmap="turbo")

    tracer_figures(run.tracers, out)
    write_report(run, args, gradients, out("report.md"))


def pile_and_seam_figure(heights, ex, ey, fill, time, tunnel_height, path):
    """Where the coal ended up: the pile in the tunnel and what is left in the seam."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), constrained_layout=True)
    top.bar(np.arange(len(heights)) + 0.5, heights, width=1.0, color="0.3")
    top.set_xlim(0, max(len(heights), 1))
    top.set_ylim(0, tunnel_height * 1.1)
    top.set_xlabel("distance from the excavation face [m]")
    top.set_ylabel("pile height [m]")
    top.set_title(f"Coal pile in the tunnel at t = {time:.3g} s")
    mesh = bottom.pcolormesh(ex, ey, fill.T, cmap="viridis", vmin=0, vmax=1)
    bottom.set_aspect("equal")
    bottom.set_xlabel("x [m]")
    bottom.set_ylabel("y [m]")
    bottom.set_title("Coal left in the seam per 1 m bin, of that at t = 0 (a cavity shows as 0)")
    fig.colorbar(mesh, ax=bottom, shrink=0.8)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def axis_row(nodes, face, mid):
    """The seepage nodes on the tunnel's axis (the row of nodes nearest y = mid:
    a mesh with an odd number of elements over the tunnel has none on it; in
    3D on the plane of symmetry z = 0) from the face inward, in order."""
    nearest = nodes[np.argmin(np.abs(nodes[:, 1] - mid)), 1]
    on_axis = (np.abs(nodes[:, 1] - nearest) < 1e-6) & (nodes[:, 0] >= face - 1e-9)
    if nodes.shape[1] == 3:
        on_axis &= np.abs(nodes[:, 2]) < 1e-6
    row = np.where(on_axis)[0]
    return row[np.argsort(nodes[row, 0])]


def steepest_drop(p, distance):
    """The steepest drop of p along the axis (per metre) and how far in it
    starts. The face recedes as coal leaves: the steepest drop is where the
    coal face stands."""
    slope = np.diff(p) / np.diff(distance)
    k = int(np.argmax(slope))
    return slope[k], distance[k]


def drop_table(g, steps):
    """The steepest drops (rows of t, drop, where) at the given rows, as a table across."""
    return ["| t [s] | " + " | ".join(f"{t:.3g}" for t in g[steps, 0]) + " |",
            "|---|" + "---|" * len(steps),
            "| drop [MPa/m] | " + " | ".join(f"{v:.3g}" for v in g[steps, 1]) + " |",
            "| at [m] | " + " | ".join(f"{v:.3g}" for v in g[steps, 2]) + " |"]


def bin_counts(x0, x, edges):
    """The particles in each bin of the edges (one array per coordinate, the
    first coordinates' in order) at t = 0 (x0) and now (x)."""
    d = len(edges)
    return np.histogramdd(x0[:, :d], bins=edges)[0], np.histogramdd(x[:, :d], bins=edges)[0]


def seam_bins(x0, x, face, right, top, h):
    """Square bins of edge h over the seam (face..right, 0..top): their edges and
    the particles in each at t = 0 (x0) and now (x)."""
    ex, ey = np.arange(face, right + 1e-9, h), np.arange(0.0, top + 1e-9, h)
    return (ex, ey, *bin_counts(x0, x, [ex, ey]))


def cavity_bins(full0, full1, opening=None):
    """The cavity among the seam's bins (particles per bin at t = 0 and now,
    along x first, the layer at the face first): the bins that held coal and
    hold less than half of it now, connected to the face through each other,
    opening through the face layer's bins that opening marks (default: all)."""
    emptied = (full0 > 0) & (full1 < 0.5 * full0)
    inside = np.zeros_like(emptied)
    mouth = emptied[0] if opening is None else emptied[0] & opening
    front = [(0, *map(int, i)) for i in np.argwhere(mouth)]
    while front:
        cell = front.pop()
        if inside[cell]:
            continue
        inside[cell] = True
        for axis in range(emptied.ndim):
            for step in (1, -1):
                n = cell[:axis] + (cell[axis] + step,) + cell[axis + 1:]
                if 0 <= n[axis] < emptied.shape[axis] and emptied[n] and not inside[n]:
                    front.append(n)
    return inside


def depth_of(bins, h):
    """How far from the face the marked bins of edge h reach [m]."""
    return (np.nonzero(bins.any(axis=tuple(range(1, bins.ndim))))[0].max() + 1) * h


def cavity(full0, full1, h):
    """The cavity in the seam's bins of edge h (cavity_bins): its area, depth
    from the face, largest height and mouth on the face, in metres."""
    inside = cavity_bins(full0, full1)
    if not inside.any():
        return {"area": 0.0, "depth": 0.0, "height": 0.0, "mouth": 0.0}
    return {"area": inside.sum() * h * h, "depth": depth_of(inside, h),
            "height": inside.sum(axis=1).max() * h, "mouth": inside[0].sum() * h}


def loose_bins(held0, held1):
    """The loosened seam coal: bins that hold less than 95 % of their coal at
    t = 0 (the void the ejected coal left, spread out)."""
    return (held0 > 0) & (held1 < 0.95 * held0)


def loosened(held0, held1, h):
    """The loosened seam coal (loose_bins) in bins of edge h: their area,
    depth from the face and the share of the coal they still hold."""
    loose = loose_bins(held0, held1)
    if not loose.any():
        return {"area": 0.0, "depth": 0.0, "fill": 1.0}
    return {"area": loose.sum() * h * h, "depth": depth_of(loose, h),
            "fill": held1[loose].sum() / held0[loose].sum()}


def ejection_start(run, face):
    """Where ejection starts: the first snapshot with coal in front of the face,
    its time [s] and the median height of that coal [m]; (None, None) if none."""
    for k in range(1, len(run.particle_files)):
        p = run.particles(k)["points"]
        out = p[:, 0] < face - 0.1
        if out.any():
            return run.times[k], float(np.median(p[out, 1]))
    return None, None


def pile_heights(x, ejected, face, floor, farthest):
    """The height of the coal above the tunnel floor [m] in 1 m bins from the
    face out to the farthest coal."""
    heights = []
    for d in np.arange(0.0, farthest, 1.0):
        sel = ejected & (x[:, 0] < face - d) & (x[:, 0] >= face - d - 1)
        heights.append(x[sel, 1].max() - floor if sel.any() else 0.0)
    return heights


def shares(e, unit):
    """What the grid transfer, the time step and the damage took of the gas
    work, from a row of mpm_history.csv whose energies are in unit ("J_per_m"
    in a plane run, "J" in 3D)."""
    work = e[f"external_work_{unit}"]
    return {"transfer_share": e[f"transfer_{unit}"] / work, "step_share": e[f"integration_{unit}"] / work,
            "damage_share": e[f"damage_{unit}"] / work}


def energy_table(e, unit, walls):
    """The energy books at a row of mpm_history.csv as a Markdown table;
    walls names what the walls' friction acts on."""
    terms = ["kinetic", "strain", "plastic", "damage", "walls", "transfer", "integration", "left_grid"]
    return [
        f"| gas work | kinetic | strain | plastic | damage | {walls} | grid transfer "
        "| time step | left the grid | balance error |",
        "|---|---|---|---|---|---|---|---|---|---|",
        f"| {e[f'external_work_{unit}']:.4g} | " + " | ".join(f"{e[f'{t}_{unit}']:.4g}" for t in terms) + " | "
        f"{e[f'balance_error_{unit}']:.4g} ({e[f'balance_error_{unit}'] / e[f'external_work_{unit}']:+.2%} of "
        "the gas work) |",
    ]


ENERGY_NOTE = ("The grid transfer is what the grid-to-particle transfer takes from the grid's update: the PIC share "
               "of the FLIP/PIC blend (or APIC) takes the velocity differences of coal within a cell, separating "
               "fragments above all, and the update's spread over each particle's nodes is lost in its "
               "interpolation. The time step is the explicit step's own energy error (negative: energy it gave); "
               "both fall with the step. The balance error is what neither holds (docs/theory/energies.md).")


def write_report(run, args, gradients, path):
    face, floor, roof = args.face, args.tunnel_floor, args.tunnel_roof
    peak = tracer_peaks(run.tracers)
    last = run.particles(len(run.particle_files) - 1)
    first = run.particles(0)
    x0 = first["points"]
    x = last["points"]
    ejected = x[:, 0] < face
    farthest = face - x[:, 0].min() if ejected.any() else 0.0
    removed = int(run.history["removed_total"][-1])
    start_time, start_height = ejection_start(run, face)
    heights = pile_heights(x, ejected, face, floor, farthest)
    right = float(run.nodes[:, 0].max())
    cav = cavity(*seam_bins(x0, x, face, right, args.top, 0.5)[2:], 0.5)
    ex1, ey1, held0, held1 = seam_bins(x0, x, face, right, args.top, 1.0)
    loose = loosened(held0, held1, 1.0)
    pile_and_seam_figure(heights, ex1, ey1, np.where(held0 > 0, held1 / np.maximum(held0, 1), np.nan),
                         run.times[-1], roof - floor, os.path.join(os.path.dirname(path), "fig10_pile_and_seam.png"))
    # At rest: the kinetic energy at the end against its peak.
    kinetic = run.coupling["kinetic_energy"]
    rest_ratio = kinetic[-1] / kinetic.max() if kinetic.max() > 0 else 0.0
    e = run.history[-1]
    released = run.coupling["gas_released"][-1]
    damaged = (last["damage"].ravel() > 0).mean()
    broken = (last["damage"].ravel() >= 0.99).mean()
    g = np.array(gradients)
    steps = np.unique(np.linspace(1, len(g) - 1, min(len(g) - 1, 10)).round().astype(int))
    lines = [
        "# Outburst case: measured figures beside the paper's",
        "",
        f"Run: `{os.path.basename(os.path.normpath(run.dir))}`, {run.times[-1]:.3g} s simulated, "
        f"{len(x0)} particles, {len(run.cells)} seepage cells; kinetic energy at the end "
        f"{rest_ratio:.1%} of its peak.",
        "",
        "| quantity | this run | paper |",
        "|---|---|---|",
        f"| peak speed, face centre (particle 2) | {peak['centre'][0]:.3g} m/s at {peak['centre'][1]:.3g} s "
        f"| {PAPER['centre']} m/s |",
        f"| peak speed, face top (particle 1) | {peak['top'][0]:.3g} m/s at {peak['top'][1]:.3g} s "
        f"| {PAPER['top']} m/s |",
        f"| peak speed, face bottom (particle 3) | {peak['bottom'][0]:.3g} m/s at {peak['bottom'][1]:.3g} s "
        f"| {PAPER['bottom']} m/s |",
        f"| final displacement top / middle / bottom | {peak['top'][2]:.3g} / {peak['centre'][2]:.3g} / "
        f"{peak['bottom'][2]:.3g} m | top farthest, then middle, then bottom |",
        "| ejection starts | " + (f"by t = {start_time:.3g} s, around y = {start_height:.3g} m "
                                  f"(face {floor:g}-{roof:g} m)" if start_time is not None else "no ejection")
        + " | mid-face |",
        f"| farthest coal from the face | {farthest:.3g} m ({removed} particles left the grid at the tunnel's "
        f"end) | 20 m |",
        f"| coal in front of the face | {ejected.sum()} particles ({ejected.mean():.1%}) | - |",
        f"| cavity (seam emptied to < half, connected to the face) | {cav['area']:.3g} m2, {cav['depth']:.3g} m "
        f"deep, {cav['height']:.3g} m at its highest, mouth {cav['mouth']:.3g} m | a large cavity with a small "
        "opening |",
        f"| loosened seam coal (1 m bins holding < 95 % of their coal) | {loose['area']:.3g} m2 to "
        f"{loose['depth']:.3g} m deep, at {loose['fill']:.0%} of its initial density | - |",
        f"| damaged / fully damaged coal | {damaged:.1%} / {broken:.1%} | damage spreads from the face inward |",
        f"| gas released into the tunnel | {released:.4g} m3 per m of depth (at the model's pressure) | - |",
        f"| steepest pressure drop on the tunnel axis | {g[1, 1]:.3g} MPa/m at {g[1, 0]:.3g} s ({g[1, 2]:.3g} m "
        f"into the seam), {g[-1, 1]:.3g} MPa/m at {g[-1, 0]:.3g} s ({g[-1, 2]:.3g} m) | largest at the face, "
        "easing with time |",
        "",
        "Pile height above the tunnel floor [m] per metre from the face out to the farthest coal "
        "(0..1 m from the face first):",
        "",
        "    " + " ".join(f"{v:.2f}" for v in heights),
        "",
        "Steepest pressure drop on the tunnel axis over time (where it sits: metres into the seam):",
        "",
        *drop_table(g, steps),
        "",
        "## Energy budget (J per m of depth, at the end)",
        "",
        *energy_table(e, "J_per_m", "roof, floor (friction)"),
        "",
        ENERGY_NOTE,
        "",
        "Figures: fig3_pressure.png, fig4_pressure_profile.png, fig5_damage.png, "
        "fig6_min_principal_stress.png, fig7_velocity.png, fig8_tracer_velocity.png, "
        "fig9_tracer_displacement.png, fig10_pile_and_seam.png (the pile and the coal left in the seam).",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
