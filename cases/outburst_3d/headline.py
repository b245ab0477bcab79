"""The 3D outburst's headline numbers from a run's output, and the plane
case's beside them, measured alike.

The 3D scene models half of the heading (z = 0 its plane of symmetry), so
what it holds in m3 (coal, gas, cavity) is half the whole heading's. To set
it beside the plane case's m3 per metre of depth, a half-model volume V is
read per metre of the heading's width: the whole heading's 2 V over its full
width 2 w (w the half-width, the face support's extent along z), V / w. The
seam beside the heading reaches to z = d (a roller wall: headings 2 d apart),
so per metre of the seam's width the same volume is V / d.
"""
import os
import re

import h5py
import numpy as np

from ..outburst.headline import CAVITY_BIN, headline as plane_headline_numbers
from ..outburst.report import (MPA, Run, axis_row, bin_counts, cavity_bins, coal_volume, depth_of,
                               loose_bins, shares, steepest_drop, tracer_peaks, tunnel)
from ..units import value

# Edge of the bins the loosened coal is measured in [m], as the plane report's.
LOOSE_BIN = 1.0


def wall_time(log, directory):
    """The wall time [s] of the run into directory, from the program's log
    (its "done: ... s wall" line, followed by "results: DIRECTORY")."""
    with open(log) as f:
        text = f.read()
    want = os.path.realpath(directory)
    for seconds, results in re.findall(r"done: .*?([0-9.eE+-]+) s wall.*?\n.*?results: (\S+)", text):
        if os.path.realpath(results) == want:
            return float(seconds)
    raise ValueError(f"{log}: no finished run into {directory} (a 'done: ... s wall' line, then 'results: ...')")


def version(run):
    with h5py.File(run.particle_files[0]) as f:
        text = f.attrs["version"]
    return text.decode() if isinstance(text, bytes) else str(text)


def run_numbers(run, where, per_metre):
    """What both cases measure alike at the run's end: the tracers, the coal in
    front of the face, damage, the loosened seam, the pressure on the axis,
    the energy books' shares and what the run was. per_metre turns the model's
    volumes into m3 per metre of width (1 in a plane run: its own unit)."""
    unit = "J" if run.dimension == 3 else "J_per_m"
    peak = tracer_peaks(run.tracers)
    face = where["face"]
    x0, last = run.particles(0)["points"], run.particles(len(run.particle_files) - 1)
    x, damage = last["points"], last["damage"].ravel()
    ejected = x[:, 0] < face
    broken = damage >= 0.99
    edges = seam_edges(run, where, LOOSE_BIN)
    held0, held1 = bin_counts(x0, x, edges)
    loose = loose_bins(held0, held1)
    row = axis_row(run.nodes, face, 0.5 * (where["floor"] + where["roof"]))
    first, (last_drop, last_at) = (steepest_drop(run.pressure(j)[row] / MPA, run.nodes[row, 0] - face)
                                   for j in (1, len(run.seepage_files) - 1))
    e = run.history[-1]
    kinetic = run.coupling["kinetic_energy"]
    # The share of the seam's section across x that the heading opens.
    section, opening = where["top"], where["roof"] - where["floor"]
    if run.dimension == 3:
        section, opening = section * float(run.nodes[:, 2].max()), opening * where["half_width"]
    return {
        "centre_m_per_s": peak["centre"][0], "top_m_per_s": peak["top"][0], "bottom_m_per_s": peak["bottom"][0],
        "centre_displacement_m": peak["centre"][2], "top_displacement_m": peak["top"][2],
        "bottom_displacement_m": peak["bottom"][2],
        "farthest_m": face - x[:, 0].min() if ejected.any() else 0.0,
        "left_grid": int(run.history["removed_total"][-1]),
        "ejected_fraction": ejected.mean(),
        "ejected_m3_per_m": ejected.mean() * coal_volume(run.scene) * per_metre,
        "damaged_fraction": (damage > 0).mean(), "fully_damaged_fraction": broken.mean(),
        "fully_damaged_m3_per_m": broken.mean() * coal_volume(run.scene) * per_metre,
        # How far into the seam the fully damaged coal reaches, from the face.
        "damage_depth_m": x[broken & ~ejected, 0].max() - face if (broken & ~ejected).any() else 0.0,
        "loosened_m2_per_m": loose.sum() * LOOSE_BIN ** len(edges) * per_metre,
        "loosened_depth_m": depth_of(loose, LOOSE_BIN) if loose.any() else 0.0,
        "loosened_fill": held1[loose].sum() / held0[loose].sum() if loose.any() else 1.0,
        "first_drop_MPa_per_m": first[0], "last_drop_MPa_per_m": last_drop, "last_drop_at_m": last_at,
        **shares(e, unit),
        # What the friction on the rock took of the gas work, and what the books leave open.
        "walls_share": e[f"walls_{unit}"] / e[f"external_work_{unit}"],
        "balance_share": e[f"balance_error_{unit}"] / e[f"external_work_{unit}"],
        "kinetic_end_share": kinetic[-1] / kinetic.max() if kinetic.max() > 0 else 0.0,
        "opening_share": opening / section,
        "simulated_s": run.times[-1], "cell_m": value(run.scene["mpm"]["grid"]["cell_size"], "m"),
        "particles": len(x0), "seepage_cells": len(run.cells),
        "mpm_steps": int(e["step"]),
        # The windows' own time, after the settling stage and without output.
        "windows_s": sum(run.coupling[c].sum() for c in ("seepage_s", "solid_s", "coupler_s")),
        "version": version(run),
    }


def seam_edges(run, where, h):
    """Bins of edge h over the seam at the start: face..its right end, floor
    of the model..the coal's top, and in 3D z = 0..the seam's far side."""
    edges = [np.arange(where["face"], float(run.nodes[:, 0].max()) + 1e-9, h), np.arange(0.0, where["top"] + 1e-9, h)]
    if run.dimension == 3:
        edges.append(np.arange(0.0, float(run.nodes[:, 2].max()) + 1e-9, h))
    return edges


def cavity(full0, full1, h, opening=None):
    """The cavity in the seam's cubic bins of edge h (x, y, z; cavity_bins of
    the plane report, opening through the face's bins that opening marks,
    default all): its volume, depth from the face, mouth on the face (an
    area), and how far it reaches from the axis z = 0 and, in any column, up."""
    inside = cavity_bins(full0, full1, opening)
    if not inside.any():
        return {"volume": 0.0, "depth": 0.0, "mouth": 0.0, "width": 0.0, "height": 0.0}
    return {"volume": inside.sum() * h ** 3, "depth": depth_of(inside, h), "mouth": inside[0].sum() * h ** 2,
            "width": (np.nonzero(inside.any(axis=(0, 1)))[0].max() + 1) * h, "height": inside.sum(axis=1).max() * h}


def headline(directory, log=None):
    """The 3D run's numbers at its end; its wall time from the program's log, if given."""
    run = Run(directory)
    if run.dimension != 3:
        raise ValueError(f"{directory}: a plane run (its grid has {run.dimension} lengths); "
                         "cases.outburst.headline measures it")
    where = tunnel(run.scene)
    face, half, far = where["face"], where["half_width"], float(run.nodes[:, 2].max())
    numbers = run_numbers(run, where, 1 / half)
    x0, last = run.particles(0)["points"], run.particles(len(run.particle_files) - 1)
    x = last["points"]
    in_seam = (last["damage"].ravel() >= 0.99) & (x[:, 0] >= face)
    released = run.coupling["gas_released"][-1]
    # A cavity opens into the heading: through the face's bins in front of it,
    # not those the floor, roof and side rock close.
    edges = seam_edges(run, where, CAVITY_BIN)
    y, z = (0.5 * (e[1:] + e[:-1]) for e in edges[1:])
    opening = ((y > where["floor"]) & (y < where["roof"]))[:, None] & (z < half)[None, :]
    hole = cavity(*bin_counts(x0, x, edges), CAVITY_BIN, opening)
    return {
        **numbers,
        "ejected_m3": numbers["ejected_m3_per_m"] * half,
        # How far from the heading's axis the fully damaged seam coal reaches.
        "damage_width_m": x[in_seam, 2].max() if in_seam.any() else 0.0,
        "loosened_m3": numbers["loosened_m2_per_m"] * half,
        "gas_released_m3": released, "gas_released_m3_per_m": released / half,
        "gas_released_m3_per_m_of_seam": released / far,
        "cavity_m3": hole["volume"], "cavity_m2_per_m": hole["volume"] / half, "cavity_depth_m": hole["depth"],
        "cavity_mouth_m2": hole["mouth"], "cavity_width_m": hole["width"], "cavity_height_m": hole["height"],
        "heading_half_width_m": half, "seam_far_side_m": far,
        # Empty without the log: not measured.
        "wall_s": wall_time(log, directory) if log else "",
    }


def plane_headline(directory):
    """The plane case's headline numbers (cases.outburst.headline) and what
    the 3D comparison adds to them."""
    run = Run(directory)
    if run.dimension != 2:
        raise ValueError(f"{directory}: not a plane run (its grid has {run.dimension} lengths)")
    return {**plane_headline_numbers(directory), **run_numbers(run, tunnel(run.scene), 1.0),
            "run": os.path.basename(os.path.normpath(directory))}
