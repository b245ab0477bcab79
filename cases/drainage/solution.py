"""The drainage case's exact solution: the self-similar half-space drainage
P = P0 f(x / sqrt(D0 t)) of model-notes section 1 (P = p^2), computed here by
ODE shooting, independently of the C++ code, for the seam of a run's scene."""
import functools

import numpy as np

from ..units import value


@functools.lru_cache
def similarity(face_ratio, z_max=10.0, dz=1e-3):
    """f(z) with f'' = -(z/2) f^(-3/4) f', f(0) = face_ratio, f(inf) = 1."""
    z = np.arange(0.0, z_max + dz, dz)

    def shoot(slope, keep=False):
        y, v = face_ratio, slope
        out = [y]
        for zi in z[:-1]:
            def rhs(zz, yy, vv):
                return -0.5 * zz * yy ** -0.75 * vv
            k1y, k1v = v, rhs(zi, y, v)
            k2y, k2v = v + 0.5 * dz * k1v, rhs(zi + 0.5 * dz, y + 0.5 * dz * k1y, v + 0.5 * dz * k1v)
            k3y, k3v = v + 0.5 * dz * k2v, rhs(zi + 0.5 * dz, y + 0.5 * dz * k2y, v + 0.5 * dz * k2v)
            k4y, k4v = v + dz * k3v, rhs(zi + dz, y + dz * k3y, v + dz * k3v)
            y += dz / 6 * (k1y + 2 * k2y + 2 * k3y + k4y)
            v += dz / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
            if keep:
                out.append(y)
            elif y > 1:
                return y
        return np.array(out) if keep else y

    lo, hi = 0.0, 1.0
    while shoot(hi) < 1:
        hi *= 2
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if shoot(mid) < 1 else (lo, mid)
    slope = 0.5 * (lo + hi)
    return z, shoot(slope, keep=True), slope


class Seam:
    """The scene's seam: its gas conductivity lambda, initial pressure p0 and
    face pressure pf [Pa], height [m], P0 = p0^2, diffusivity D0 and f."""

    def __init__(self, s):
        region = s["seepage"]["regions"][0]
        self.conductivity = value(region["lambda"], "m2/(Pa2 s)")
        content = value(region["gas_content_coefficient"], "Pa^-0.5")
        self.p0 = value(region["initial_pressure"], "Pa")
        self.pf = value(s["seepage"]["boundaries"][0]["value"], "Pa")
        self.height = value(s["seepage"]["mesh"]["size"][1], "m")
        self.squared = self.p0 ** 2
        self.d0 = 4 * self.conductivity * self.squared ** 0.75 / content
        self.z, self.f, self.slope = similarity((self.pf / self.p0) ** 2)

    def pressure(self, x, t):
        """p [Pa] at distance x from the face at time t."""
        return self.p0 * np.sqrt(np.interp(x / np.sqrt(self.d0 * t), self.z, self.f, right=1.0))

    def released(self, t):
        """Gas released through the face by time t, per face area [m3/m2]."""
        return 2 * self.conductivity * self.squared * self.slope * np.sqrt(t / self.d0)
