"""Figures and report of the 3D outburst (outburst_3d.toml), beside the plane
case's and the paper's.

usage: python3 -m cases.outburst_3d.report RESULTS_DIR [--plane PLANE_RESULTS_DIR] [--log LOG]

writes into RESULTS_DIR: report.md, headline.csv (the 3D run's numbers, one
row), with --plane headline_plane.csv (the plane run's, measured alike), and
the figures: fig3_pressure.png (the seepage on the plane of symmetry z = 0),
fig4_pressure_profile.png (on the heading's axis), fig5_damage.png,
fig6_min_principal_stress.png and fig7_velocity.png (particles in the slab of
one particle spacing against z = 0), fig8_tracer_velocity.png and
fig9_tracer_displacement.png, fig10_pile_and_seam.png (the heap's height along
the heading, the seam's coal left on the plane of symmetry),
fig11_heap_plan.png (the heap from above), fig12_damage_mid_height.png
(damage in the slab at the heading's mid-height, x-z) and
fig13_seam_fill_plan.png (the seam's coal left at the heading's height, x-z).
--log names the program's log, whose "done" line gives the run's wall time.

Everything else is read from the run's own files, as cases.outburst.report
reads a plane run (whose figures these are, on sections of the heading).
"""
import argparse
import math
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..outburst.report import (MPA, PAPER, ENERGY_NOTE, Run, axis_row, bin_counts, drop_table, ejection_start,
                               energy_table, five, particle_figure, pile_and_seam_figure, pile_heights, pressure_figure,
                               pressure_profile_figure, section, tracer_figures, tunnel)
from ..runs import write_rows
from ..units import value
from .headline import LOOSE_BIN, headline, plane_headline, seam_edges


def spacing(s):
    """The particles' spacing at the start [m]: the grid's cell over the particles per cell along each axis."""
    return value(s["mpm"]["grid"]["cell_size"], "m") / s["mpm"]["bodies"][0]["particles_per_cell"]


def faces_on_plane(nodes, cells, z=0.0):
    """The hexahedra's faces on the plane z (m x 4 node indices, each face's
    corners in turn around it), for drawing a field of the nodes there."""
    on = np.abs(nodes[cells, 2] - z) < 1e-9
    quads = []
    for cell, mask in zip(cells, on):
        if mask.sum() != 4:
            continue
        corners = cell[mask]
        xy = nodes[corners, :2]
        turn = np.argsort(np.arctan2(*(xy - xy.mean(axis=0)).T[::-1]))
        quads.append(corners[turn])
    return np.array(quads)


def side_frame(left, face, right, half, depth):
    """What frames an x-z section of the model: the side rock beside the
    heading (left..face, z = half..depth) and the model's extent."""
    def frame(ax):
        ax.add_patch(plt.Rectangle((left, half), face - left, depth - half, color="0.75", zorder=0))
        ax.set_xlim(left, right)
        ax.set_ylim(0, depth)
        ax.set_ylabel("z [m]")
    return frame


def heap_plan_figure(x, left, face, floor, half, time, path, h=0.25):
    """The coal in front of the face from above: its top's height above the
    floor in columns of h x h, the modelled half (z >= 0) and its mirror image."""
    ahead = x[:, 0] < face
    reach = face - x[ahead, 0].min() if ahead.any() else 1.0
    ex = np.arange(face - h * math.ceil(reach / h), face + 1e-9, h)
    ez = np.arange(-half, half + 1e-9, h)
    top = np.full((len(ex) - 1, len(ez) - 1), np.nan)
    i = np.clip(np.searchsorted(ex, x[ahead, 0], side="right") - 1, 0, len(ex) - 2)
    for z in (x[ahead, 2], -x[ahead, 2]):
        j = np.clip(np.searchsorted(ez, z, side="right") - 1, 0, len(ez) - 2)
        np.fmax.at(top, (i, j), x[ahead, 1] - floor)
    fig, ax = plt.subplots(figsize=(11, 3.2), constrained_layout=True)
    mesh = ax.pcolormesh(ex, ez, top.T, cmap="viridis", vmin=0)
    ax.axhline(0, color="k", lw=0.6, ls="--")
    ax.set_xlim(left, face)
    ax.set_ylim(-half, half)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"Coal in front of the face at t = {time:.3g} s from above: height of its top above the floor\n"
                 f"(columns of {h:g} m; z < 0 mirrors the model about its plane of symmetry z = 0)", fontsize=9)
    fig.colorbar(mesh, ax=ax, shrink=0.9, label="height [m]")
    fig.savefig(path, dpi=130)
    plt.close(fig)


def seam_fill_plan_figure(held0, held1, edges, floor, roof, time, path):
    """The seam's coal left at the heading's height (the bins between its floor
    and roof, summed over y), of that at t = 0, in the x-z plane."""
    band = slice(int(round(floor / LOOSE_BIN)), int(round(roof / LOOSE_BIN)))
    before, now = held0[:, band, :].sum(axis=1), held1[:, band, :].sum(axis=1)
    fill = np.where(before > 0, now / np.maximum(before, 1), np.nan)
    fig, ax = plt.subplots(figsize=(9, 3.6), constrained_layout=True)
    mesh = ax.pcolormesh(edges[0], edges[2], fill.T, cmap="viridis", vmin=0, vmax=1)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"Coal left in the seam at t = {time:.3g} s, y = {floor:g}-{roof:g} m (the heading's height), "
                 f"per {LOOSE_BIN:g} m column, of that at t = 0", fontsize=9)
    fig.colorbar(mesh, ax=ax, shrink=0.9)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def figures(run, out):
    """Every figure of the 3D run; the steepest drops on the heading's axis (t, MPa/m, m into the seam)."""
    where = tunnel(run.scene)
    face, floor, roof, top, half = (where[k] for k in ("face", "floor", "roof", "top", "half_width"))
    left, right, depth = float(run.nodes[:, 0].min()), float(run.nodes[:, 0].max()), float(run.nodes[:, 2].max())
    frame = section((left, face, floor, roof, top, right))
    picks, seep_picks = five(len(run.particle_files)), five(len(run.seepage_files))
    pressure_figure(run, seep_picks, faces_on_plane(run.nodes, run.cells), frame,
                    "Gas pressure p [MPa] on the plane of symmetry z = 0 (Fig. 3)", out("fig3_pressure.png"))
    gradients = pressure_profile_figure(run, axis_row(run.nodes, face, 0.5 * (floor + roof)), face, seep_picks,
                                        out("fig4_pressure_profile.png"))
    gap = spacing(run.scene)
    slab = lambda p: p["points"][:, 2] < gap
    on_plane = f" on the plane of symmetry (particles at z < {gap:g} m)"
    particle_figure(run, picks, lambda p: p["damage"].ravel(), f"Damage D{on_plane} (Fig. 5)", out("fig5_damage.png"),
                    frame, cmap="inferno_r", vmin=0, vmax=1, select=slab)
    particle_figure(run, picks, lambda p: p["sigma_min"].ravel() / MPA,
                    f"Minimum principal effective stress [MPa], tension positive,{on_plane} (Fig. 6)",
                    out("fig6_min_principal_stress.png"), frame, cmap="coolwarm", select=slab)
    particle_figure(run, picks, lambda p: np.linalg.norm(p["velocity"], axis=1),
                    f"Particle speed [m/s]{on_plane} (Fig. 7)", out("fig7_velocity.png"), frame, cmap="turbo",
                    select=slab)
    tracer_figures(run.tracers, out)
    mid = 0.5 * (floor + roof)
    particle_figure(run, picks, lambda p: p["damage"].ravel(),
                    f"Damage D at the heading's mid-height (particles at |y - {mid:g} m| < {gap:g} m), from above",
                    out("fig12_damage_mid_height.png"), side_frame(left, face, right, half, depth), cmap="inferno_r",
                    vmin=0, vmax=1, select=lambda p: np.abs(p["points"][:, 1] - mid) < gap, columns=(0, 2))

    x0, x = run.particles(0)["points"], run.particles(len(run.particle_files) - 1)["points"]
    ejected = x[:, 0] < face
    farthest = face - x[:, 0].min() if ejected.any() else 0.0
    edges = seam_edges(run, where, LOOSE_BIN)
    held0, held1 = bin_counts(x0, x, edges)
    # The seam's section on the plane of symmetry: the layer of bins against z = 0.
    pile_and_seam_figure(pile_heights(x, ejected, face, floor, farthest), edges[0], edges[1],
                         np.where(held0[:, :, 0] > 0, held1[:, :, 0] / np.maximum(held0[:, :, 0], 1), np.nan),
                         run.times[-1], roof - floor, out("fig10_pile_and_seam.png"))
    heap_plan_figure(x, left, face, floor, half, run.times[-1], out("fig11_heap_plan.png"))
    seam_fill_plan_figure(held0, held1, edges, floor, roof, run.times[-1], out("fig13_seam_fill_plan.png"))
    return gradients


# The comparison's rows: a label, then how a 3D row and a plane row of
# numbers read in it, and the paper's. Shared by report.md and the
# manual's generated tables (cases.readme_tables: docs/cases/outburst-3d.md, docs/cases/outburst.md).
def _triple(h, key, unit):
    return " / ".join(f"{h[f'{k}_{key}']:.3g}" for k in ("centre", "top", "bottom")) + f" {unit}"


def _shares(h):
    return (f"{h['transfer_share']:.1%} / {h['walls_share']:.1%} / {h['step_share']:.2%} / "
            f"{h['balance_share']:.1e}")


def _run(h):
    return f"{h['simulated_s']:.3g} s, {h['particles']:.0f}, {h['seepage_cells']:.0f}, {h['mpm_steps']:.0f}"


ROWS = [
    ("peak speed, face centre / top / bottom", lambda h: _triple(h, "m_per_s", "m/s"),
     lambda h: _triple(h, "m_per_s", "m/s"), f"{PAPER['centre']} / {PAPER['top']} / {PAPER['bottom']} m/s"),
    ("final displacement, centre / top / bottom", lambda h: _triple(h, "displacement_m", "m"),
     lambda h: _triple(h, "displacement_m", "m"), "top farthest, then middle, then bottom"),
    ("farthest coal from the face (run-out)", lambda h: f"{h['farthest_m']:.3g} m",
     lambda h: f"{h['farthest_m']:.3g} m", f"{PAPER['farthest']:g} m"),
    ("particles that left the grid", lambda h: f"{h['left_grid']:.0f}", lambda h: f"{h['left_grid']:.0f}", "-"),
    ("coal in front of the face", lambda h: f"{h['ejected_fraction']:.1%} of the particles: {h['ejected_m3']:.3g} m3 "
     f"(half model), {h['ejected_m3_per_m']:.3g} m3 per m of heading width",
     lambda h: f"{h['ejected_fraction']:.1%} of the particles: {h['ejected_m3_per_m']:.3g} m3/m", "-"),
    ("damaged / fully damaged coal", lambda h: f"{h['damaged_fraction']:.1%} / {h['fully_damaged_fraction']:.1%}",
     lambda h: f"{h['damaged_fraction']:.1%} / {h['fully_damaged_fraction']:.1%}", "from the face inward"),
    ("fully damaged coal: per m of width; how far into the seam and from the axis",
     lambda h: f"{h['fully_damaged_m3_per_m']:.3g} m3 per m of heading width; {h['damage_depth_m']:.3g} m, "
     f"{h['damage_width_m']:.3g} m",
     lambda h: f"{h['fully_damaged_m3_per_m']:.3g} m3/m; {h['damage_depth_m']:.3g} m", "-"),
    ("gas released", lambda h: f"{h['gas_released_m3']:.4g} m3 (half model): {h['gas_released_m3_per_m']:.4g} m3 per "
     f"m of heading width, {h['gas_released_m3_per_m_of_seam']:.4g} per m of seam width",
     lambda h: f"{h['gas_released_m3_per_m']:.4g} m3/m", "-"),
    ("cavity (seam bins of 0.5 m emptied below half, open to the heading)",
     lambda h: f"{h['cavity_m3']:.3g} m3 (half model), {h['cavity_m2_per_m']:.3g} m2 per m of heading width; "
     f"{h['cavity_depth_m']:.3g} m deep, {h['cavity_width_m']:.3g} m from the axis, mouth "
     f"{h['cavity_mouth_m2']:.3g} m2",
     lambda h: f"{h['cavity_m2_per_m']:.3g} m2/m, {h['cavity_depth_m']:.3g} m deep, mouth {h['cavity_mouth_m']:.3g} m",
     "a large cavity with a small opening"),
    ("loosened seam (1 m bins holding < 95 % of their coal)",
     lambda h: f"{h['loosened_m3']:.3g} m3 (half model), {h['loosened_depth_m']:.3g} m deep, at "
     f"{h['loosened_fill']:.0%} of its density",
     lambda h: f"{h['loosened_m2_per_m']:.3g} m2/m, {h['loosened_depth_m']:.3g} m deep, at "
     f"{h['loosened_fill']:.0%} of its density", "-"),
    ("steepest pressure drop on the axis, first output -> end (m into the seam at the end)",
     lambda h: f"{h['first_drop_MPa_per_m']:.3g} -> {h['last_drop_MPa_per_m']:.3g} MPa/m ({h['last_drop_at_m']:.3g} m)",
     lambda h: f"{h['first_drop_MPa_per_m']:.3g} -> {h['last_drop_MPa_per_m']:.3g} MPa/m ({h['last_drop_at_m']:.3g} m)",
     "largest at the face, easing"),
    ("energy books, of the gas work: grid transfer / friction on the rock / time step / balance error",
     _shares, _shares, "-"),
    ("run: simulated, particles, seepage cells, MPM steps", _run, _run, "-"),
    ("wall time (the coupling windows' own)",
     lambda h: (f"{h['wall_s']:.0f} s" if h["wall_s"] != "" else "-") + f" ({h['windows_s']:.0f} s)",
     lambda h: f"- ({h['windows_s']:.0f} s)", "-"),
]


def comparison(runs, plane=None):
    """The table of 3D runs' numbers (runs: pairs of a column title and a run's
    headline) beside the plane run's, if given, and the paper's."""
    lines = ["| quantity | " + "".join(f"{title} | " for title, _ in runs) + ("plane case | " if plane else "")
             + "paper |",
             "|---|" + "---|" * len(runs) + ("---|" if plane else "") + "---|"]
    for label, ours, theirs, paper in ROWS:
        lines.append(f"| {label} | " + "".join(f"{ours(h)} | " for _, h in runs)
                     + (f"{theirs(plane)} | " if plane else "") + f"{paper} |")
    return lines


def ratios(h, plane):
    """The 3D numbers over the plane's, volumes per metre of the heading's width."""
    pairs = [("centre speed", "centre_m_per_s"), ("run-out", "farthest_m"),
             ("coal in front of the face", "ejected_m3_per_m"), ("fully damaged coal", "fully_damaged_m3_per_m"),
             ("its depth into the seam", "damage_depth_m"), ("gas released", "gas_released_m3_per_m"),
             ("friction's share of the gas work", "walls_share")]
    return "; ".join(f"{label} {h[key] / plane[key]:.2f}" if plane[key] else f"{label} - (plane 0)"
                     for label, key in pairs)


def differences(h, plane=None):
    """What the heading's geometry changes against the plane case, from the run's own numbers."""
    half, far = h["heading_half_width_m"], h["seam_far_side_m"]
    return (
        "What the third dimension changes. The plane case is a heading of unbounded width: each metre of its face "
        "drains and sheds the seam straight behind it. Here the heading, "
        f"{2 * half:g} m wide among headings {2 * far:g} m apart, opens {h['opening_share']:.0%} of the seam's "
        "section across it" + (f" (the plane case's tunnel {plane['opening_share']:.0%})" if plane else "")
        + ", so per metre of heading width the "
        f"seam holds {far / half:g} times the plane case's coal and gas, and gas reaches the face's coal from "
        "beside the heading as well as from behind it. Coal broken beside the heading has no face of its own: it "
        f"leaves only through the opening, and the fully damaged coal reaches {h['damage_width_m']:.3g} m from the "
        f"heading's axis (the seam's far side is {far:g} m from it) and {h['damage_depth_m']:.3g} m into the seam. "
        "In the heading the jet rubs on the side rock as well as on the floor (friction's share of the gas work "
        "in the table)." + (f" The cells are {h['cell_m']:.3g} m against the plane case's {plane['cell_m']:.3g} m: "
                           "part of each difference may be the resolution's."
                           if plane and h["cell_m"] != plane["cell_m"] else ""))


def write_report(run, h, plane, plane_dir, gradients, path):
    g = np.array(gradients)
    steps = np.unique(np.linspace(1, len(g) - 1, min(len(g) - 1, 10)).round().astype(int))
    start_time, start_height = ejection_start(run, tunnel(run.scene)["face"])
    start = (f"Coal first stands in front of the face by t = {start_time:.3g} s, around y = {start_height:.3g} m."
             if start_time is not None else "No coal stands in front of the face at any output.")
    lines = [
        "# 3D outburst at a heading: measured figures beside the plane case's and the paper's",
        "",
        f"Run: `{os.path.basename(os.path.normpath(run.dir))}` ({h['version']}), {h['simulated_s']:.3g} s simulated, "
        f"{h['particles']:.0f} particles, {h['seepage_cells']:.0f} seepage hexahedra; kinetic energy at the end "
        f"{h['kinetic_end_share']:.1%} of its peak. {start}"
        + (f" The plane case: `{os.path.basename(os.path.normpath(plane_dir))}` ({plane['version']})." if plane else ""),
        "",
        f"The model is half of a heading {2 * h['heading_half_width_m']:g} m wide (z = 0 its plane of symmetry) in a "
        f"seam reaching z = {h['seam_far_side_m']:g} m (headings {2 * h['seam_far_side_m']:g} m apart). Its volumes "
        "(coal, gas, cavity) are the half model's; per metre of heading width they are the whole heading's (twice "
        f"the half model's) over its width {2 * h['heading_half_width_m']:g} m, beside the plane case's per metre of "
        f"depth; per metre of seam width, over the {2 * h['seam_far_side_m']:g} m between headings. The tracers "
        "are the particles nearest the face's top, middle and bottom on the heading's axis.",
        "",
        *comparison([("3D heading", h)], plane),
        "",
    ]
    if plane:
        lines += [f"3D over plane: {ratios(h, plane)}.", ""]
    lines += [
        differences(h, plane),
        "",
        "Steepest pressure drop on the heading's axis (y at mid-height, z = 0) over time (where it sits: metres into "
        "the seam):",
        "",
        *drop_table(g, steps),
        "",
        "## Energy budget (J, the half model, at the end)",
        "",
        *energy_table(run.history[-1], "J", "roof, floor, side (friction)"),
        "",
        ENERGY_NOTE,
        "",
        "Figures: fig3_pressure.png (the pressure on the plane of symmetry), fig4_pressure_profile.png (on the "
        "heading's axis), fig5_damage.png, fig6_min_principal_stress.png, fig7_velocity.png (the particles against "
        "the plane of symmetry), fig8_tracer_velocity.png, fig9_tracer_displacement.png, fig10_pile_and_seam.png "
        "(the heap's height along the heading; the seam's coal left against the plane of symmetry), "
        "fig11_heap_plan.png (the heap from above), fig12_damage_mid_height.png (damage at the heading's "
        "mid-height, from above: how it spreads beside the heading), fig13_seam_fill_plan.png (the seam's coal "
        "left at the heading's height, from above: the cavity's sideways extent).",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--plane", help="a run of the plane case (cases/outburst/outburst.toml) to set beside it")
    ap.add_argument("--log", help="the 3D run's log (its wall time)")
    args = ap.parse_args(argv)
    run = Run(args.results)
    out = lambda name: os.path.join(args.results, name)
    h = headline(args.results, args.log)
    plane = None
    if args.plane:
        plane = plane_headline(args.plane)
        write_rows(out("headline_plane.csv"), [plane])
    write_rows(out("headline.csv"), [h])
    gradients = figures(run, out)
    write_report(run, h, plane, args.plane, gradients, out("report.md"))


if __name__ == "__main__":
    main()
