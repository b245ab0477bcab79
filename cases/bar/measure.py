"""Error of a bar run (bar.toml) against the analytic series: the free-end
tracer's displacement over the whole run, RMS over the tip's largest
displacement v0 L / c. The bar's length, speed and wave speed are the run's own
(its scene). For cases.study."""
import math
import os

import numpy as np

from ..run_output import scene
from ..units import value


def bar(s):
    """Length L [m], initial speed v0 [m/s] and wave speed c [m/s] of the scene's bar."""
    body = s["mpm"]["bodies"][0]
    material = next(m for m in s["mpm"]["materials"] if m["name"] == body["material"])
    length = value(body["box_max"][0], "m") - value(body["box_min"][0], "m")
    speed = math.sqrt(value(material["youngs_modulus"], "Pa") / value(material["density"], "kg/m3"))
    return length, value(body["initial_velocity"][0], "m/s"), speed


def exact(x, t, length, v0, c):
    """u(x, t) of the bar stopped at x = 0, by its modes."""
    k = (2 * np.arange(1, 2001) - 1) * np.pi / (2 * length)
    modes = 2 * v0 / (length * c * k ** 2) * np.sin(k * x)
    return (modes[None, :] * np.sin(np.outer(t, c * k))).sum(axis=1)


def errors(run_dir):
    length, v0, c = bar(scene(run_dir))
    tr = np.genfromtxt(os.path.join(run_dir, "tracers.csv"), delimiter=",", names=True)
    x0 = tr["x_m"][0] - tr["ux_m"][0]
    u = exact(x0, tr["time_s"], length, v0, c)
    return {"tip_displacement": float(np.sqrt(np.mean((tr["ux_m"] - u) ** 2)) / (v0 * length / c))}
