"""The outburst's headline numbers from a run's output: what its sensitivity
study, its ensembles and its accuracy study (measure.py) compare."""
from .report import MPA, Run, axis_row, steepest_drop, tunnel


def headline(directory):
    run = Run(directory)
    where = tunnel(run.scene)
    face, axis = where["face"], 0.5 * (where["floor"] + where["roof"])
    tr = run.tracers
    speed = {k: tr["speed_m_per_s"][tr["tracer"] == k].max() for k in range(3)}
    last = run.particles(-1)
    x, damage = last["points"], last["damage"].ravel()
    ejected = x[:, 0] < face
    # The steepest pressure drop on the tunnel's axis at the first output and the last.
    row = axis_row(run.nodes, face, axis)
    drops = [steepest_drop(run.pressure(k)[row] / MPA, run.nodes[row, 0] - face)[0] for k in (1, -1)]
    return {
        "centre_m_per_s": speed[1], "top_m_per_s": speed[0], "bottom_m_per_s": speed[2],
        "farthest_m": face - x[:, 0].min() if ejected.any() else 0.0,
        "ejected_fraction": ejected.mean(),
        "fully_damaged_fraction": (damage >= 0.99).mean(),
        "gas_released_m3_per_m": run.coupling["gas_released"][-1],
        "left_grid": int(run.history["removed_total"][-1]),
        "first_drop_MPa_per_m": drops[0], "last_drop_MPa_per_m": drops[1],
        # What the transfer and the time step took, of the gas work.
        "transfer_share": run.history["transfer_J_per_m"][-1] / run.history["external_work_J_per_m"][-1],
        "step_share": run.history["integration_J_per_m"][-1] / run.history["external_work_J_per_m"][-1],
    }
