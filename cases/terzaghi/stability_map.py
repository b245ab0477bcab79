"""The stability map of the poroelastic window schemes: predicted by
coupler/stability.hpp (through build/coupler/coupling-stability) and measured
by a sweep of Terzaghi runs, on one figure.

usage: python3 -m cases.terzaghi.stability_map [--out DIR] [--build build] [--jobs N]

For two Biot coefficients and four schemes (implicit with the pressure ramp,
implicit with the end pressure and the fixed-stress split, explicit with the
ramp, explicit with the fixed-stress split), over the window and the fluid's
stiffness S M (S the storage coefficient, M the column's constrained modulus):
the background is the predicted growth rate of the fastest mode (white: every
mode decays), the markers the growth measured in runs of terzaghi.toml (the
kinetic energy's rate over the second half of a 0.3 s run, or up to its
blow-up, halved: an amplitude's rate). The window axis is made dimensionless
by the consolidation coefficient c_v = (k/mu) / (S + alpha^2 / M) and the
seepage cell h. Runs with a scheme the analysis predicts unstable run with
coupling.allow_unstable = true. Writes DIR/map.png, DIR/predicted.csv and
DIR/measured.csv (default DIR: cases/terzaghi/stability).
"""
import argparse
import concurrent.futures
import csv
import os
import subprocess
import tempfile
import tomllib

import numpy as np

from ..runs import run_one
from ..units import value
from .measure import Column

HERE = os.path.dirname(os.path.abspath(__file__))

SCENE = os.path.join(HERE, "terzaghi.toml")
with open(SCENE, "rb") as _f:
    _scene = tomllib.load(_f)
# The scene's column: constrained modulus, mobility, seepage cell height.
_column = Column(_scene)
M, MOBILITY = _column.modulus, _column.mobility
CELL = value(_scene["seepage"]["mesh"]["size"][1], "m") / _scene["seepage"]["mesh"]["cells"][1]
SCHEMES = {  # label: overrides
    "implicit, ramp": ['coupling.scheme="implicit"', 'coupling.window_pressure="ramp"'],
    "implicit, end + fixed stress": ['coupling.scheme="implicit"', 'coupling.window_pressure="end"',
                                     "coupling.fixed_stress=true"],
    "explicit, ramp": ['coupling.scheme="explicit"', 'coupling.window_pressure="ramp"'],
    "explicit, ramp + fixed stress": ['coupling.scheme="explicit"', 'coupling.window_pressure="ramp"',
                                      "coupling.fixed_stress=true"],
}
# How each scheme reads in coupling-stability's rows.
ROWS = {"implicit, ramp": ("implicit", "ramp", "0"), "implicit, end + fixed stress": ("implicit", "end", "0"),
        "explicit, ramp": ("explicit", "ramp", "0"), "explicit, ramp + fixed stress": ("explicit", "ramp", "1")}
BIOT = [0.5, 1.0]
# Below this a measured rate is noise: over the 0.15 s it is fitted on, the
# kinetic energy of a slowly consolidating column drifts by a factor of a few.
NOISE = 5.0
MEASURED_SM = [1.2, 0.1, 0.01, 0.001]
MEASURED_WINDOWS_MS = [20, 10, 5, 2.5, 1.25]


def storage(sm):
    return sm / M


def consolidation(alpha, sm):
    return MOBILITY / (storage(sm) + alpha ** 2 / M)


def physics(alpha, sm, window_ms):
    return [f'seepage.regions[0].storage_coefficient="{storage(sm):.6g} Pa^-1"', f"coupling.biot_coefficient={alpha}",
            f'coupling.window="{window_ms:.6g} ms"']


def predict(program, alpha, sm, window_ms):
    command = [program, SCENE, "-q"] + [x for o in physics(alpha, sm, window_ms) for x in ("--set", o)]
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    rows = list(csv.DictReader(done.stdout.splitlines()))
    return {label: float(next(r["growth_per_s"] for r in rows
                              if (r["scheme"], r["window_pressure"], r["fixed_stress"]) == key))
            for label, key in ROWS.items()}


def measured_growth(run_dir):
    """Half the kinetic energy's growth rate over the second half of the windows run."""
    with open(os.path.join(run_dir, "coupling.csv")) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time"]) for r in rows])
    kinetic = np.array([float(r["kinetic_energy"]) for r in rows])
    half = len(t) // 2
    keep = kinetic[half:] > 0
    if keep.sum() < 3:
        return float("nan")
    return 0.5 * np.polyfit(t[half:][keep], np.log(kinetic[half:][keep]), 1)[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(HERE, "stability"))
    ap.add_argument("--build", default=os.path.join(HERE, "..", "..", "build"))
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    stability = os.path.join(args.build, "coupler", "coupling-stability")
    outburst = os.path.join(args.build, "coupler", "outburst")
    os.makedirs(args.out, exist_ok=True)

    # Predicted, on a fine grid.
    windows = np.geomspace(0.3, 40, 22)  # ms
    sms = np.geomspace(3e-4, 4, 18)
    predicted = []
    for alpha in BIOT:
        for sm in sms:
            for w in windows:
                growth = predict(stability, alpha, sm, w)
                predicted += [{"biot": alpha, "SM": sm, "window_ms": w, "scheme": k, "growth_per_s": g}
                              for k, g in growth.items()]
    with open(os.path.join(args.out, "predicted.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(predicted[0]))
        writer.writeheader()
        writer.writerows(predicted)

    # Measured.
    plan = [(alpha, sm, w, label) for alpha in BIOT for sm in MEASURED_SM for w in MEASURED_WINDOWS_MS
            for label in SCHEMES]
    measured = []
    with tempfile.TemporaryDirectory() as scratch, concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = {}
        for i, (alpha, sm, w, label) in enumerate(plan):
            overrides = physics(alpha, sm, w) + SCHEMES[label] + [
                'scene.end_time="0.3 s"', "coupling.allow_unstable=true", "coupling.max_iterations=300",
                'coupling.on_divergence="continue"']
            futures[pool.submit(run_one, outburst, SCENE, overrides, os.path.join(scratch, f"run_{i:03d}"), 1)] = \
                (i, alpha, sm, w, label)
        for future in concurrent.futures.as_completed(futures):
            i, alpha, sm, w, label = futures[future]
            wall, note = future.result()
            growth = measured_growth(os.path.join(scratch, f"run_{i:03d}"))
            row = {"biot": alpha, "SM": sm, "window_ms": w, "scheme": label, "growth_per_s": growth,
                   "predicted_per_s": predict(stability, alpha, sm, w)[label], "wall_s": wall,
                   "blew_up": int(bool(note)), "note": note}
            measured.append(row)
            print(f"  alpha {alpha}, S M {sm:g}, window {w:g} ms, {label}: measured {growth:.3g} 1/s, predicted "
                  f"{row['predicted_per_s']:.3g} 1/s {note[:60]}", flush=True)
    measured.sort(key=lambda r: (r["biot"], r["scheme"], r["SM"], r["window_ms"]))
    with open(os.path.join(args.out, "measured.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(measured[0]))
        writer.writeheader()
        writer.writerows(measured)
    plot(predicted, measured, windows, sms, os.path.join(args.out, "map.png"))
    agree = [r for r in measured if (r["growth_per_s"] > NOISE) == (r["predicted_per_s"] > NOISE)]
    print(f"stability map: {len(measured)} runs; the prediction classifies {len(agree)} of them as measured "
          f"(growing faster than {NOISE:g} 1/s or not); {os.path.join(args.out, 'map.png')}")
    for r in measured:
        if r not in agree:
            print(f"  differs: alpha {r['biot']}, S M {r['SM']:g}, window {r['window_ms']:g} ms, {r['scheme']}: "
                  f"measured {r['growth_per_s']:.3g} 1/s, predicted {r['predicted_per_s']:.3g} 1/s")


def plot(predicted, measured, windows, sms, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import SymLogNorm

    norm = SymLogNorm(linthresh=10, vmin=-300, vmax=300)
    fig, axes = plt.subplots(len(BIOT), len(SCHEMES), figsize=(4.2 * len(SCHEMES), 3.8 * len(BIOT)),
                             sharex=False, sharey=True, constrained_layout=True)
    for row, alpha in enumerate(BIOT):
        for col, label in enumerate(SCHEMES):
            ax = axes[row][col]
            grid = np.full((len(sms), len(windows)), np.nan)
            for r in predicted:
                if r["biot"] == alpha and r["scheme"] == label:
                    grid[list(sms).index(r["SM"]), list(windows).index(r["window_ms"])] = r["growth_per_s"]
            x = np.outer(np.ones_like(sms), windows * 1e-3) * np.array(
                [[consolidation(alpha, sm) / CELL ** 2] for sm in sms])
            y = np.outer(sms, np.ones_like(windows))
            mesh = ax.pcolormesh(x, y, grid, cmap="RdBu_r", norm=norm, shading="gouraud")
            if np.nanmax(grid) > 0 > np.nanmin(grid):
                ax.contour(x, y, grid, levels=[0], colors="k", linewidths=1)
            for r in measured:
                if r["biot"] != alpha or r["scheme"] != label:
                    continue
                xm = r["window_ms"] * 1e-3 * consolidation(alpha, r["SM"]) / CELL ** 2
                unstable = r["growth_per_s"] > NOISE
                ax.scatter([xm], [r["SM"]], c=[r["growth_per_s"]], cmap="RdBu_r", norm=norm, s=70,
                           marker="X" if unstable else "o", edgecolors="k", linewidths=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"{label}, alpha = {alpha}", fontsize=9)
            if row == len(BIOT) - 1:
                ax.set_xlabel("window c_v / h^2")
            if col == 0:
                ax.set_ylabel("S M (fluid compliance / solid's)")
    fig.colorbar(mesh, ax=axes, label="growth rate of the fastest mode [1/s]")
    fig.suptitle("Terzaghi column: background and black line predicted (coupler/stability.hpp), markers measured "
                 f"(X: grows faster than {NOISE:g} 1/s)", fontsize=10)
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
