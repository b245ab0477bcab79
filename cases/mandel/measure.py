"""Errors of a Mandel run (mandel.toml) against the analytic series
(Abousleiman et al. 1996) at the run's last output: pore pressure (RMS over the
seepage nodes, over p0) and the settlement of the top particles (relative,
against the plate's). The specimen's values are the run's own (its scene).
For cases.study."""
import numpy as np

from ..run_output import particle_state, scene, seepage_state
from ..units import value


class Specimen:
    """The scene's quarter a x b under the plate's force F per metre of depth:
    its moduli, Skempton's B, the undrained Poisson ratio nu_u, the
    consolidation coefficient c, the undrained pressure p0 and the series'
    roots."""

    def __init__(self, s):
        material, region, body = s["mpm"]["materials"][0], s["seepage"]["regions"][0], s["mpm"]["bodies"][0]
        e, self.nu = value(material["youngs_modulus"], "Pa"), material["poisson_ratio"]
        storage = value(region["storage_coefficient"], "1/Pa")
        mobility = value(region["permeability"], "m2") / value(region["viscosity"], "Pa s")
        alpha = s["coupling"]["biot_coefficient"]
        self.a = value(body["box_max"][0], "m") - value(body["box_min"][0], "m")
        self.b = value(body["box_max"][1], "m") - value(body["box_min"][1], "m")
        self.force = -value(s["mpm"]["platens"][0]["force"], "N/m")
        self.shear = e / (2 * (1 + self.nu))
        bulk = e / (3 * (1 - 2 * self.nu))
        undrained_bulk = bulk + alpha ** 2 / storage
        self.skempton = alpha / storage / undrained_bulk
        self.nu_u = (3 * undrained_bulk - 2 * self.shear) / (2 * (3 * undrained_bulk + self.shear))
        self.c = mobility / storage * (bulk + 4 * self.shear / 3) / (undrained_bulk + 4 * self.shear / 3)
        self.p0 = self.force * self.skempton * (1 + self.nu_u) / (3 * self.a)
        self.roots = self._roots(300)

    def _roots(self, count):
        """tan(x) = k x: sin x - k x cos x changes sign once in (0, pi/2) and in each (n pi, n pi + pi/2)."""
        k = (1 - self.nu) / (self.nu_u - self.nu)
        n = np.arange(count)
        lo, hi = np.maximum(n * np.pi, 1e-9), n * np.pi + np.pi / 2
        f = lambda x: np.sin(x) - k * x * np.cos(x)
        rising = f(lo) < 0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            below = (f(mid) < 0) == rising
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        return 0.5 * (lo + hi)

    def pressure(self, x, t):
        r, a = self.roots[None, :], self.a
        x = np.atleast_1d(x)[:, None]
        terms = np.sin(r) / (r - np.sin(r) * np.cos(r)) * (np.cos(r * x / a) - np.cos(r)) * \
            np.exp(-r * r * self.c * t / a ** 2)
        return 2 * self.force * self.skempton * (1 + self.nu_u) / (3 * a) * terms.sum(axis=1)

    def settlement(self, t):
        r, a = self.roots, self.a
        terms = np.sin(r) * np.cos(r) / (r - np.sin(r) * np.cos(r)) * np.exp(-r * r * self.c * t / a ** 2)
        return -self.b * self.force / (self.shear * a) * (-(1 - self.nu) / 2 + (1 - self.nu_u) * terms.sum())


def errors(run_dir):
    specimen = Specimen(scene(run_dir))
    t, nodes, p = seepage_state(run_dir)
    rms = float(np.sqrt(np.mean((p - specimen.pressure(nodes[:, 0], t)) ** 2)) / specimen.p0)
    x0, u = particle_state(run_dir)
    top = x0[:, 1] > x0[:, 1].max() - 1e-9
    return {"pressure": rms, "settlement": abs(-u[top, 1].mean() / specimen.settlement(t) - 1)}
