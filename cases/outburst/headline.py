"""The outburst's headline numbers from a run's output: what its sensitivity
study, its ensembles and its accuracy study (measure.py) compare."""
from .report import MPA, Run, axis_row, steepest_drop

FACE = 25.0
TUNNEL_AXIS = 4.5  # between the floor (3 m) and the roof (6 m)


def headline(directory):
    run = Run(directory)
    tr = run.tracers
    speed = {k: tr["speed_m_per_s"][tr["tracer"] == k].max() for k in range(3)}
    last = run.particles(-1)
    x, damage = last["points"], last["damage"].ravel()
    ejected = x[:, 0] < FACE
    # The steepest pressure drop on the tunnel's axis at the first output and the last.
    row = axis_row(run.nodes, FACE, TUNNEL_AXIS)
    drops = [steepest_drop(run.pressure(k)[row] / MPA, run.nodes[row, 0] - FACE)[0] for k in (1, -1)]
    return {
        "centre_m_per_s": speed[1], "top_m_per_s": speed[0], "bottom_m_per_s": speed[2],
        "farthest_m": FACE - x[:, 0].min() if ejected.any() else 0.0,
        "ejected_fraction": ejected.mean(),
        "fully_damaged_fraction": (damage >= 0.99).mean(),
        "gas_released_m3_per_m": run.coupling["gas_released"][-1],
        "left_grid": int(run.history["removed_total"][-1]),
        "first_drop_MPa_per_m": drops[0], "last_drop_MPa_per_m": drops[1],
        # What the transfer and the time step took, of the gas work.
        "transfer_share": run.history["transfer_J_per_m"][-1] / run.history["external_work_J_per_m"][-1],
        "step_share": run.history["integration_J_per_m"][-1] / run.history["external_work_J_per_m"][-1],
    }
