"""The 3D granular collapse (cases/granular_collapse_3d): its quarter column is
a quarter cylinder, and a coarse run of it (cells of R0 / 8, 3 thousand
particles; CTest's "shipped scene granular_collapse_3d runs") spreads as far
as Lube et al.'s axisymmetric columns, within the band below, and comes to
rest whole."""
import math
import os
import tomllib

import pytest

from cases.granular_collapse_3d import measure
from cases.units import value

SCENE = "cases/granular_collapse_3d/granular_collapse_3d.toml"
# The coarse run's (R_inf - R0) / R0 over Lube's 1.24 a: within 30 %. A
# sanity band, as the 2D case's: a Drucker-Prager continuum cannot hold the
# experiments' independence of the grains' friction (the outer cone, 1.4
# times as steep as the shipped inner one, stops the column short of the
# band: README.md), and the run-out still moves with the cells; far outside
# it, the column is too stiff, the floor frictionless, or the scheme has
# fluidised the sand.
BAND = (0.7, 1.3)


def test_the_strips_make_a_quarter_cylinder(repo):
    with open(os.path.join(repo, SCENE), "rb") as f:
        s = tomllib.load(f)
    strips = sorted(([value(x, "m") for x in b["box_min"]], [value(x, "m") for x in b["box_max"]])
                    for b in s["mpm"]["bodies"])
    reach = strips[-1][1][0]
    for k, (lo, hi) in enumerate(strips):
        # Side by side from the axis, all as high, each from the wall z = 0
        # as deep as the circle's mean depth over its width.
        assert lo[0] == (strips[k - 1][1][0] if k else 0.0)
        assert (lo[1], hi[1], lo[2]) == (0.0, strips[0][1][1], 0.0)
        mean_depth = quarter_circle_area(reach, lo[0], hi[0]) / (hi[0] - lo[0])
        assert hi[2] == pytest.approx(mean_depth, abs=1e-6)
    r0, h0 = measure.column(s)
    print(f"{len(strips)} strips to x = {reach} m: R0 = {r0:.7f} m from their footprint, H0 = {h0} m")
    assert r0 == pytest.approx(reach, rel=1e-6)


def quarter_circle_area(r, x0, x1):
    """The area under z = sqrt(r^2 - x^2) from x0 to x1."""
    F = lambda x: 0.5 * (x * math.sqrt(max(r * r - x * x, 0.0)) + r * r * math.asin(x / r))
    return F(x1) - F(x0)


def test_lube_scaling_changes_law_where_the_two_meet():
    linear, root = measure.lube(1.0), measure.lube(4.0) / 2
    assert (linear, root) == (pytest.approx(1.24), pytest.approx(1.6))
    # 1.24 a = 1.6 a^(1/2) at a = 1.665, where Lube et al. put the change (1.7).
    assert (root / linear) ** 2 == pytest.approx(1.7, abs=0.05)
    assert measure.lube(1.6) == pytest.approx(1.24 * 1.6) and measure.lube(1.8) == pytest.approx(1.6 * math.sqrt(1.8))


def test_coarse_column_runs_out_as_lube_and_comes_to_rest(collapse_3d_run):
    r = measure.run_out(collapse_3d_run)
    ratio = r["spread"] / r["lube_spread"]
    print(f"3D granular collapse, a = {r['aspect_ratio']:.3f}, {r['particles']} particles of {r['spacing_m']} m: "
          f"(R_inf - R0) / R0 = {r['spread']:.3f} against Lube's {r['lube_spread']:.3f} (ratio {ratio:.2f}, band "
          f"{BAND}); along the walls {r['spread_along_walls']:.3f}, the diagonal {r['spread_along_diagonal']:.3f}; "
          f"H_inf / H0 = {r['H_inf_m'] / r['H0_m']:.3f}; fastest particle at t = {r['time_s']} s "
          f"{r['fastest_m_per_s']:.3g} m/s; {r['removed']} removed")
    assert r["aspect_ratio"] == pytest.approx(1.0, rel=1e-5)
    assert BAND[0] < ratio < BAND[1]
    assert r["H_inf_m"] < r["H0_m"]
    assert r["fastest_m_per_s"] < 0.05
    assert r["removed"] == 0
