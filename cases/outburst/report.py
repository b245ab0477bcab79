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
    [m] in an outburst scene: the face is the support removed at t = 0."""
    support = [o for o in s["mpm"].get("obstacles", []) if o.get("support", False)]
    if len(support) != 1:
        raise ValueError(f"the scene has {len(support)} face supports (obstacles with support = true), not one")
    (x0, y0), (x1, y1) = ([value(c, "m") for c in support[0][k]] for k in ("box_min", "box_max"))
    top = max(value(b["box_max"][1], "m") for b in s["mpm"]["bodies"])
    return {"face": x1, "floor": y0, "roof": y1, "top": top}


def initial_pressure(s):
    """The largest gas pressure at t = 0 [Pa], the pressure figure's scale."""
    return max(value(r["initial_pressure"], "Pa") for r in s["seepage"]["regions"])


class Run:
    def __init__(self, d):
        self.dir = d
        self.particle_files = sorted(glob.glob(os.path.join(d, "particles_*.h5")))
        self.seepage_files = sorted(glob.glob(os.path.join(d, "seepage_0*.h5")))
        self.times = times_of(os.path.join(d, "particles.xdmf"))
        self.seepage_times = times_of(os.path.join(d, "seepage.xdmf"))
        with h5py.File(os.path.join(d, "seepage_mesh.h5")) as f:
            self.nodes = f["nodes"][:, :2]
            self.cells = f["cells"][:]
        self.tracers = np.genfromtxt(os.path.join(d, "tracers.csv"), delimiter=",", names=True)
        self.history = np.genfromtxt(os.path.join(d, "mpm_history.csv"), delimiter=",", names=True)
        self.coupling = np.genfromtxt(os.path.join(d, "coupling.csv"), delimiter=",", names=True)
        self.scene = scene(d)

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


def particle_figure(run, picks, field, label, path, geometry, cmap="viridis", vmin=None, vmax=None):
    fig, axes = panel_grid(len(picks), label)
    for ax, k in zip(axes, picks):
        p = run.particles(k)
        values = field(p)
        draw_rock(ax, *geometry[:5])
        sc = ax.scatter(p["points"][:, 0], p["points"][:, 1], c=values, s=1.5, cmap=cmap, vmin=vmin, vmax=vmax,
                        linewidths=0)
        ax.set_aspect("equal")
        ax.set_xlim(geometry[0], geometry[5])
        ax.set_ylim(0, geometry[4])
        ax.set_title(f"t = {run.times[k]:.3g} s (snapshot {k})", fontsize=9)
        fig.colorbar(sc, ax=ax, shrink=0.9)
    axes[-1].set_xlabel("x [m]")
    fig.savefig(path, dpi=130)
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
    geometry = (left, face, floor, roof, top, width)
    out = lambda name: os.path.join(args.results, name)
    picks = five(len(run.particle_files))
    seep_picks = five(len(run.seepage_files))

    # Fig. 3: gas pressure on the seepage mesh.
    fig, axes = panel_grid(len(seep_picks), "Gas pressure p [MPa] (Fig. 3)")
    polys = run.nodes[run.cells]
    for ax, k in zip(axes, seep_picks):
        p = run.pressure(k) / MPA
        coll = PolyCollection(polys, array=p[run.cells].mean(axis=1), cmap="jet", edgecolors="none")
        coll.set_clim(0, initial_pressure(run.scene) / MPA)
        ax.add_collection(coll)
        draw_rock(ax, *geometry[:5])
        ax.set_xlim(left, width)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_title(f"t = {run.seepage_times[k]:.3g} s", fontsize=9)
        fig.colorbar(coll, ax=ax, shrink=0.9)
    axes[-1].set_xlabel("x [m]")
    fig.savefig(out("fig3_pressure.png"), dpi=130)
    plt.close(fig)

    # Fig. 4: pressure against distance from the face, along the tunnel's axis.
    mid = 0.5 * (floor + roof)
    row = axis_row(run.nodes, face, mid)
    fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
    gradients = []
    for k in range(len(run.seepage_files)):
        p = run.pressure(k)[row] / MPA
        distance = run.nodes[row, 0] - face
        gradients.append((run.seepage_times[k], *steepest_drop(p, distance)))
        if k in seep_picks or k == 0:
            ax.plot(distance, p, marker=".", label=f"t = {run.seepage_times[k]:.3g} s")
    ax.set_xlabel("distance from the excavation face [m]")
    ax.set_ylabel("gas pressure p [MPa]")
    ax.set_title(f"Gas pressure along the tunnel axis (y = {run.nodes[row[0], 1]:.3g} m) (Fig. 4)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(out("fig4_pressure_profile.png"), dpi=130)
    plt.close(fig)

    # Figs. 5-7: damage, minimum principal stress, speed.
    particle_figure(run, picks, lambda p: p["damage"].ravel(), "Damage D (Fig. 5)", out("fig5_damage.png"),
                    geometry, cmap="inferno_r", vmin=0, vmax=1)
    particle_figure(run, picks, lambda p: p["sigma_min"].ravel() / MPA,
                    "Minimum principal effective stress [MPa], tension positive (Fig. 6)",
                    out("fig6_min_principal_stress.png"), geometry, cmap="coolwarm")
    particle_figure(run, picks, lambda p: np.linalg.norm(p["velocity"], axis=1), "Particle speed [m/s] (Fig. 7)",
                    out("fig7_velocity.png"), geometry, cmap="turbo")

    # Figs. 8-9: tracers at the top, middle and bottom of the face.
    names = {0: "particle 1 (top)", 1: "particle 2 (middle)", 2: "particle 3 (bottom)"}
    tr = run.tracers
    for column, label, path, title in (
            ("speed_m_per_s", "speed [m/s]", "fig8_tracer_velocity.png", "Tracer speed (Fig. 8)"),
            (None, "displacement [m]", "fig9_tracer_displacement.png", "Tracer displacement (Fig. 9)")):
        fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
        for k in range(3):
            sel = tr["tracer"] == k
            values = tr[column][sel] if column else np.hypot(tr["ux_m"][sel], tr["uy_m"][sel])
            ax.plot(tr["time_s"][sel], values, label=names[k])
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend()
        fig.savefig(out(path), dpi=130)
        plt.close(fig)

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
    a mesh with an odd number of elements over the tunnel has none on it) from
    the face inward, in order."""
    nearest = nodes[np.argmin(np.abs(nodes[:, 1] - mid)), 1]
    row = np.where((np.abs(nodes[:, 1] - nearest) < 1e-6) & (nodes[:, 0] >= face - 1e-9))[0]
    return row[np.argsort(nodes[row, 0])]


def steepest_drop(p, distance):
    """The steepest drop of p along the axis (per metre) and how far in it
    starts. The face recedes as coal leaves: the steepest drop is where the
    coal face stands."""
    slope = np.diff(p) / np.diff(distance)
    k = int(np.argmax(slope))
    return slope[k], distance[k]


def seam_bins(x0, x, face, right, top, h):
    """Square bins of edge h over the seam (face..right, 0..top): their edges and
    the particles in each at t = 0 (x0) and now (x)."""
    ex, ey = np.arange(face, right + 1e-9, h), np.arange(0.0, top + 1e-9, h)
    return (ex, ey, np.histogram2d(x0[:, 0], x0[:, 1], bins=[ex, ey])[0],
            np.histogram2d(x[:, 0], x[:, 1], bins=[ex, ey])[0])


def cavity(full0, full1, h):
    """The cavity in the seam's bins of edge h (particles per bin at t = 0 and
    now, the first row of bins at the face): the bins that held coal and hold
    less than half of it now, connected to the face. Its area, depth from the
    face, largest height and mouth on the face, in metres."""
    emptied = (full0 > 0) & (full1 < 0.5 * full0)
    inside = np.zeros_like(emptied)
    front = [(0, j) for j in range(emptied.shape[1]) if emptied[0, j]]
    while front:
        i, j = front.pop()
        if inside[i, j]:
            continue
        inside[i, j] = True
        for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if 0 <= a < emptied.shape[0] and 0 <= b < emptied.shape[1] and emptied[a, b] and not inside[a, b]:
                front.append((a, b))
    if not inside.any():
        return {"area": 0.0, "depth": 0.0, "height": 0.0, "mouth": 0.0}
    return {"area": inside.sum() * h * h, "depth": (np.nonzero(inside.any(axis=1))[0].max() + 1) * h,
            "height": inside.sum(axis=1).max() * h, "mouth": inside[0].sum() * h}


def loosened(held0, held1, h):
    """The loosened seam coal: bins of edge h that hold less than 95 % of their
    coal at t = 0 (the void the ejected coal left, spread out). Their area,
    depth from the face and the share of the coal they still hold."""
    loose = (held0 > 0) & (held1 < 0.95 * held0)
    if not loose.any():
        return {"area": 0.0, "depth": 0.0, "fill": 1.0}
    return {"area": loose.sum() * h * h, "depth": (np.nonzero(loose.any(axis=1))[0].max() + 1) * h,
            "fill": held1[loose].sum() / held0[loose].sum()}


def write_report(run, args, gradients, path):
    face, floor, roof = args.face, args.tunnel_floor, args.tunnel_roof
    tr = run.tracers
    peak = {}
    for k, name in enumerate(("top", "centre", "bottom")):
        sel = tr["tracer"] == k
        i = np.argmax(tr["speed_m_per_s"][sel])
        peak[name] = (tr["speed_m_per_s"][sel][i], tr["time_s"][sel][i], np.hypot(tr["ux_m"][sel], tr["uy_m"][sel])[-1])
    last = run.particles(len(run.particle_files) - 1)
    first = run.particles(0)
    x0 = first["points"]
    x = last["points"]
    ejected = x[:, 0] < face
    farthest = face - x[:, 0].min() if ejected.any() else 0.0
    removed = int(run.history["removed_total"][-1])
    # Where ejection starts: the first snapshot with coal in front of the face.
    start_time, start_height = None, None
    for k in range(1, len(run.particle_files)):
        p = run.particles(k)["points"]
        out = p[:, 0] < face - 0.1
        if out.any():
            start_time = run.times[k]
            start_height = float(np.median(p[out, 1]))
            break
    # Pile: height of the coal above the tunnel floor in 1 m bins from the face
    # out to the farthest coal.
    heights = []
    for d in np.arange(0.0, farthest, 1.0):
        sel = ejected & (x[:, 0] < face - d) & (x[:, 0] >= face - d - 1)
        heights.append(x[sel, 1].max() - floor if sel.any() else 0.0)
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
        f"Run: `{os.path.abspath(run.dir)}`, {run.times[-1]:.3g} s simulated, "
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
        "| t [s] | " + " | ".join(f"{t:.3g}" for t in g[steps, 0]) + " |",
        "|---|" + "---|" * len(steps),
        "| drop [MPa/m] | " + " | ".join(f"{v:.3g}" for v in g[steps, 1]) + " |",
        "| at [m] | " + " | ".join(f"{v:.3g}" for v in g[steps, 2]) + " |",
        "",
        "## Energy budget (J per m of depth, at the end)",
        "",
        "| gas work | kinetic | strain | plastic | damage | roof, floor (friction) | grid transfer "
        "| time step | left the grid | balance error |",
        "|---|---|---|---|---|---|---|---|---|---|",
        f"| {e['external_work_J_per_m']:.4g} | {e['kinetic_J_per_m']:.4g} | {e['strain_J_per_m']:.4g} | "
        f"{e['plastic_J_per_m']:.4g} | {e['damage_J_per_m']:.4g} | {e['walls_J_per_m']:.4g} | "
        f"{e['transfer_J_per_m']:.4g} | {e['integration_J_per_m']:.4g} | {e['left_grid_J_per_m']:.4g} | "
        f"{e['balance_error_J_per_m']:.4g} ({e['balance_error_J_per_m'] / e['external_work_J_per_m']:+.2%} of "
        "the gas work) |",
        "",
        "The grid transfer is what the grid-to-particle transfer takes from the grid's update: the PIC share "
        "of the FLIP/PIC blend (or APIC) takes the velocity differences of coal within a cell, separating "
        "fragments above all, and the update's spread over each particle's nodes is lost in its "
        "interpolation. The time step is the explicit step's own energy error (negative: energy it gave); "
        "both fall with the step. The balance error is what neither holds (mpm_solid/README.md, Energies).",
        "",
        "Figures: fig3_pressure.png, fig4_pressure_profile.png, fig5_damage.png, "
        "fig6_min_principal_stress.png, fig7_velocity.png, fig8_tracer_velocity.png, "
        "fig9_tracer_displacement.png, fig10_pile_and_seam.png (the pile and the coal left in the seam).",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
