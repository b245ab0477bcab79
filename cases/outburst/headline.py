"""The outburst's headline numbers from a run's output: what its sensitivity
study, its ensembles and its accuracy study (measure.py) compare."""
import numpy as np

from .report import MPA, Run, axis_row, cavity, seam_bins, shares, steepest_drop, tracer_peaks, tunnel

# Edge of the bins the cavity is measured in [m]: one size for every
# resolution, so that runs on other grids measure alike.
CAVITY_BIN = 0.5


def headline(directory, time=None):
    """The headline numbers at the run's end, or at the snapshot at `time` [s]."""
    run = Run(directory)
    k = len(run.times) - 1
    if time is not None:
        k = int(np.argmin(np.abs(np.asarray(run.times) - time)))
        if abs(run.times[k] - time) > 1e-6 * max(1.0, time):
            raise ValueError(f"{directory}: no particle snapshot at t = {time:g} s")
    # At the end, every row of the histories; at a time, those up to it.
    t = run.times[k] if time is not None else float("inf")
    where = tunnel(run.scene)
    face, axis = where["face"], 0.5 * (where["floor"] + where["roof"])
    tr = run.tracers[run.tracers["time_s"] <= t + 1e-9]
    history = run.history[run.history["time_s"] <= t + 1e-9][-1]
    coupling = run.coupling[run.coupling["time"] <= t + 1e-9][-1]
    peak = tracer_peaks(tr)
    last = run.particles(k)
    x, damage = last["points"], last["damage"].ravel()
    ejected = x[:, 0] < face
    # The steepest pressure drop on the tunnel's axis at the first output and at t.
    row = axis_row(run.nodes, face, axis)
    seepage_k = len(run.seepage_times) - 1
    if time is not None:
        seepage_k = int(np.argmin(np.abs(np.asarray(run.seepage_times) - t)))
        if abs(run.seepage_times[seepage_k] - t) > 1e-6 * max(1.0, t):
            raise ValueError(f"{directory}: no seepage snapshot at t = {t:g} s")
    drops = [steepest_drop(run.pressure(j)[row] / MPA, run.nodes[row, 0] - face)[0] for j in (1, seepage_k)]
    hole = cavity(*seam_bins(run.particles(0)["points"], x, face, float(run.nodes[:, 0].max()), where["top"],
                             CAVITY_BIN)[2:], CAVITY_BIN)
    return {
        "centre_m_per_s": peak["centre"][0], "top_m_per_s": peak["top"][0], "bottom_m_per_s": peak["bottom"][0],
        "farthest_m": face - x[:, 0].min() if ejected.any() else 0.0,
        "ejected_fraction": ejected.mean(),
        "fully_damaged_fraction": (damage >= 0.99).mean(),
        "gas_released_m3_per_m": coupling["gas_released"],
        "left_grid": int(history["removed_total"]),
        "first_drop_MPa_per_m": drops[0], "last_drop_MPa_per_m": drops[1],
        "cavity_m2_per_m": hole["area"], "cavity_depth_m": hole["depth"], "cavity_height_m": hole["height"],
        "cavity_mouth_m": hole["mouth"],
        # What the transfer and the time step took, of the gas work, and the
        # damage: the energy a fracture energy could change.
        **shares(history, "J_per_m"),
    }
