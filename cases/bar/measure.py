"""Error of a bar run (bar.toml) against the analytic series: the free-end
tracer's displacement over the whole run, RMS over the tip's largest
displacement v0 L / c. For cases/study.py."""
import os

import numpy as np

# The scene's values (bar.toml).
L, V0, C = 1.0, 0.01, 10.0


def exact(x, t):
    """u(x, t) of the bar stopped at x = 0, by its modes."""
    k = (2 * np.arange(1, 2001) - 1) * np.pi / (2 * L)
    modes = 2 * V0 / (L * C * k ** 2) * np.sin(k * x)
    return (modes[None, :] * np.sin(np.outer(t, C * k))).sum(axis=1)


def errors(run_dir):
    tr = np.genfromtxt(os.path.join(run_dir, "tracers.csv"), delimiter=",", names=True)
    x0 = tr["x_m"][0] - tr["ux_m"][0]
    u = exact(x0, tr["time_s"])
    return {"tip_displacement": float(np.sqrt(np.mean((tr["ux_m"] - u) ** 2)) / (V0 * L / C))}
