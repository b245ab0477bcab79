"""Errors of a Terzaghi run (terzaghi.toml) against the analytic series, at the
run's last output: pore pressure (RMS over the seepage nodes, over p0) and the
settlement of the top particles (relative). The column's values are the run's
own (its scene). For cases.study."""
import numpy as np

from ..run_output import particle_state, scene, seepage_state
from ..units import value


class Column:
    """The scene's column: its height H, load q, Biot coefficient alpha,
    constrained modulus M and mobility k / mu, the undrained pressure p0 and
    the consolidation coefficient c_v."""

    def __init__(self, s):
        material, region, body = s["mpm"]["materials"][0], s["seepage"]["regions"][0], s["mpm"]["bodies"][0]
        e, nu = value(material["youngs_modulus"], "Pa"), material["poisson_ratio"]
        storage = value(region["storage_coefficient"], "1/Pa")
        self.mobility = value(region["permeability"], "m2") / value(region["viscosity"], "Pa s")
        self.alpha = s["coupling"]["biot_coefficient"]
        self.height = value(body["box_max"][1], "m") - value(body["box_min"][1], "m")
        self.load = -value(s["mpm"]["tractions"][0]["traction"][1], "Pa")
        self.modulus = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
        self.p0 = self.alpha * self.load / (self.alpha ** 2 + storage * self.modulus)
        self.cv = self.mobility / (storage + self.alpha ** 2 / self.modulus)

    def pressure(self, z, t):
        """p at depth z below the drained top."""
        m = np.pi * (2 * np.arange(400) + 1) / 2
        z = np.atleast_1d(z)[:, None]
        h = self.height
        return (2 * self.p0 / m * np.sin(m * z / h) * np.exp(-m * m * self.cv * t / h ** 2)).sum(axis=1)

    def settlement(self, y, t):
        """Downward displacement at height y: the strain (q - alpha p) / M integrated from the bottom."""
        at = (np.arange(200) + 0.5) * y / 200
        return float(((self.load - self.alpha * self.pressure(self.height - at, t)) / self.modulus).sum() * y / 200)


def errors(run_dir):
    column = Column(scene(run_dir))
    t, nodes, p = seepage_state(run_dir)
    rms = float(np.sqrt(np.mean((p - column.pressure(column.height - nodes[:, 1], t)) ** 2)) / column.p0)
    x0, u = particle_state(run_dir)
    top = x0[:, 1] > x0[:, 1].max() - 1e-9
    measured = -u[top, 1].sum()
    expected = sum(column.settlement(y, t) for y in x0[top, 1])
    return {"pressure": rms, "settlement": abs(measured / expected - 1)}
