"""The pressure at the centre of Cryer's sphere (cryer.toml) against the
analytic series (Verruijt 2016), over every output of a run: the sphere's
values are the run's own (its scene)."""
import glob
import os

import h5py
import numpy as np

from ..run_output import scene
from ..units import value


class Sphere:
    """The scene's sphere of radius a: eta, the consolidation coefficient c_v,
    the pressure the fluid starts above the open space's (p0) and the
    series' roots, the positive x of (1 - eta x^2 / 2) tan x = x."""

    def __init__(self, s):
        material, region, body = s["mpm"]["materials"][0], s["seepage"]["regions"][0], s["mpm"]["bodies"][0]
        e, nu = value(material["youngs_modulus"], "Pa"), material["poisson_ratio"]
        storage = value(region["storage_coefficient"], "1/Pa")
        mobility = value(region["permeability"], "m2") / value(region["viscosity"], "Pa s")
        alpha = s["coupling"]["biot_coefficient"]
        bulk, shear = e / (3 * (1 - 2 * nu)), e / (2 * (1 + nu))
        oedometric = bulk + 4 * shear / 3
        self.a = value(body["radius"], "m")
        self.eta = (1 - nu) / (1 - 2 * nu) * (1 + bulk * storage / alpha ** 2)
        self.cv = mobility * oedometric / (alpha ** 2 + storage * oedometric)
        self.open = value(s["coupling"]["open_pressure"], "Pa")
        self.p0 = value(region["initial_pressure"], "Pa") - self.open
        # (1 - eta x^2 / 2) sin x - x cos x has no poles: bracket its sign
        # changes on a fine lattice and bisect.
        f = lambda x: (1 - self.eta * x * x / 2) * np.sin(x) - x * np.cos(x)
        x = np.arange(0.01, 1300, 0.01)
        change = np.nonzero(np.signbit(f(x[:-1])) != np.signbit(f(x[1:])))[0]
        lo, hi = x[change], x[change + 1]
        rising = f(lo) < 0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            below = (f(mid) < 0) == rising
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        self.roots = 0.5 * (lo + hi)

    def centre(self, t):
        """p(0, t) / p0."""
        x = self.roots[None, :]
        t = np.atleast_1d(t)[:, None]
        terms = (np.sin(x) - x) / ((self.eta - 1) * np.sin(x) + self.eta * x * np.cos(x) / 2) * \
            np.exp(-x * x * self.cv * t / self.a ** 2)
        return self.eta * terms.sum(axis=1)


def centre_history(run_dir):
    """Times [s] and the pressure at the seepage node at the origin over p0,
    from every snapshot."""
    sphere = Sphere(scene(run_dir))
    with h5py.File(os.path.join(run_dir, "seepage_mesh.h5")) as f:
        centre = int(np.argmin(np.linalg.norm(f["nodes"][:], axis=1)))
    times, pressures = [], []
    for path in sorted(glob.glob(os.path.join(run_dir, "seepage_0*.h5"))):
        with h5py.File(path) as f:
            times.append(float(f.attrs["time"]))
            pressures.append((f["mesh/p"][centre] - sphere.open) / sphere.p0)
    return sphere, np.array(times), np.array(pressures)


def errors(run_dir):
    """Over the outputs after t = 0: the RMS and the largest error of the
    centre's pressure over p0, its peak, and the exact peak over the same
    times."""
    sphere, t, p = centre_history(run_dir)
    later = t > 0
    exact = sphere.centre(t[later])
    error = p[later] - exact
    return {"centre_rms": float(np.sqrt(np.mean(error ** 2))), "centre_worst": float(np.abs(error).max()),
            "peak": float(p[later].max()), "exact_peak": float(exact.max())}
