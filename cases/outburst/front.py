"""How fast the damage front and the gas-drainage front advance into the seam,
per run of the convergence study, and how that speed scales with the cell.

usage: python3 -m cases.outburst.front [--runs results/outburst_convergence] [--out cases/outburst/convergence]
writes OUT/front.csv (a row per law, cell and snapshot), OUT/front_speeds.csv
(a row per law and cell: each front's fitted speed) and OUT/front.png.

The seam lies at x > face; every front is a distance from the face, measured
within the face's height band (floor..roof, tunnel() of report.py):
- damage_farthest_m: the farthest particle in the band with D >= 0.99. One
  stray broken particle sets it: a wall or a patch of diffuse damage deep in
  the seam reads as the front.
- damage_front_m: the depth at which the share of particles with D >= 0.99,
  in bins of 0.5 m along x over the band, first falls below 50 % (linear
  between bin centres). It follows the broken zone joined to the face and
  ignores stray particles ahead of it; the bins are one size at every cell,
  as headline.py's cavity bins, so the runs measure alike. Empty bins are
  passed over: the coal that left them was broken.
- drainage_front_m: on the seepage nodes along the tunnel's axis (axis_row),
  where the pressure first rises above half the initial seam pressure (the
  pressure at t = 0 at the node farthest from the face), linear between nodes;
  empty when the whole axis has drained below it.
A front's speed is the least-squares slope over the snapshots from 0.1 s on
where it is inside the seam (short of the last bin before the seam's end);
speed ~ h^-a is fitted over the cells with a speed, per law and front.
"""
import argparse
import glob
import json
import os
import re
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..runs import write_rows
from ..units import value
from .report import Run, axis_row, tunnel

BIN = 0.5
BROKEN = 0.99
FIT_FROM = 0.1
# Each front: its column in front.csv (its speed's columns in front_speeds.csv
# take the name without "_m"), its label.
FRONTS = [("damage_farthest_m", "damage front, farthest D >= 0.99"),
          ("damage_front_m", "damage front, bins < 50 % broken"),
          ("drainage_front_m", "gas-drainage front, p > p0/2 on the axis")]
RUN_NAME = re.compile(r"^([a-z_]+?)_(\d+)_(\d+)$")


def damage_fronts(points, damage, where, right):
    """The farthest broken particle's and the bins' damage front [m from the face]."""
    x, y = points[:, 0], points[:, 1]
    band = (y >= where["floor"]) & (y <= where["roof"]) & (x >= where["face"])
    broken = band & (damage >= BROKEN)
    farthest = x[broken].max() - where["face"] if broken.any() else 0.0
    edges = np.arange(where["face"], right + 1e-9, BIN)
    held = np.histogram(x[band], edges)[0]
    share = np.histogram(x[broken], edges)[0] / np.maximum(held, 1)
    centres = 0.5 * (edges[:-1] + edges[1:]) - where["face"]
    last_broken = None
    for c, s, n in zip(centres, share, held):
        if n == 0:
            continue
        if s < 0.5:
            if last_broken is None:
                return farthest, 0.0
            c0, s0 = last_broken
            return farthest, c0 + (s0 - 0.5) / (s0 - s) * (c - c0)
        last_broken = (c, s)
    return farthest, right - where["face"]


def drainage_front(p, distance, half):
    """Where p along the axis first rises above half [m from the face]; NaN once it is below everywhere."""
    above = np.nonzero(p > half)[0]
    if not above.size:
        return np.nan
    i = above[0]
    if i == 0:
        return 0.0
    return distance[i - 1] + (half - p[i - 1]) / (p[i] - p[i - 1]) * (distance[i] - distance[i - 1])


def measure(d, law, label):
    """A row per snapshot of the run in d."""
    run = Run(d)
    where = tunnel(run.scene)
    h = value(run.scene["mpm"]["grid"]["cell_size"], "m")
    right = float(run.nodes[:, 0].max())
    row = axis_row(run.nodes, where["face"], 0.5 * (where["floor"] + where["roof"]))
    distance = run.nodes[row, 0] - where["face"]
    half = 0.5 * run.pressure(0)[row][-1]
    rows = []
    for k, t in enumerate(run.times[:len(run.particle_files)]):
        p = run.particles(k)
        farthest, front = damage_fronts(p["points"], p["damage"].ravel(), where, right)
        j = int(np.argmin(np.abs(np.asarray(run.seepage_times) - t)))
        if abs(run.seepage_times[j] - t) < 1e-6 and j < len(run.seepage_files):
            drained = drainage_front(run.pressure(j)[row], distance, half)
        else:
            print(f"{d}: no seepage snapshot at t = {t:.3g} s", file=sys.stderr)
            drained = np.nan
        released = run.coupling["gas_released"][run.coupling["time"] <= t + 1e-9]
        rows.append({"law": law, "cell": label, "h_m": h, "time_s": round(t, 6), "damage_farthest_m": farthest,
                     "damage_front_m": front, "drainage_front_m": drained,
                     "gas_released_m3_per_m": released[-1] if released.size else 0.0,
                     "seam_depth_m": right - where["face"]})
    if len(rows) < len(run.times):
        print(f"{d}: {len(run.times)} snapshot times but {len(rows)} particle files", file=sys.stderr)
    return rows


def speed(rows, key):
    """Slope [m/s] of the front over the snapshots from FIT_FROM where it is
    inside the seam, and how many snapshots that is."""
    t = np.array([r["time_s"] for r in rows])
    f = np.array([r[key] for r in rows], dtype=float)
    inside = (t >= FIT_FROM - 1e-9) & np.isfinite(f) & (f < rows[0]["seam_depth_m"] - BIN)
    if inside.sum() < 2:
        return np.nan, int(inside.sum())
    return np.polyfit(t[inside], f[inside], 1)[0], int(inside.sum())


def exponent(h, v):
    """a of v ~ h^-a over the cells with a positive speed."""
    ok = np.isfinite(v) & (v > 0)
    return -np.polyfit(np.log(h[ok]), np.log(v[ok]), 1)[0] if ok.sum() >= 2 else np.nan


def speeds(rows):
    out = []
    for law in sorted({r["law"] for r in rows}):
        cells = sorted({r["h_m"] for r in rows if r["law"] == law}, reverse=True)
        mine = [[r for r in rows if r["law"] == law and r["h_m"] == h] for h in cells]
        # Speed ~ 1/h would make each front's ratio to the next coarser cell this one.
        table = [{"law": law, "cell": m[0]["cell"], "h_m": m[0]["h_m"],
                  "cell_ratio": cells[i - 1] / cells[i] if i else np.nan} for i, m in enumerate(mine)]
        for key, _ in FRONTS:
            name = key.removesuffix("_m")
            fitted = [speed(m, key) for m in mine]
            v = np.array([s for s, _ in fitted])
            a = exponent(np.array(cells), v)
            for i, (entry, (s, n)) in enumerate(zip(table, fitted)):
                entry[f"{name}_m_per_s"] = s
                entry[f"{name}_points"] = n
                entry[f"{name}_ratio"] = s / v[i - 1] if i else np.nan
                entry[f"{name}_exponent"] = a
        out += table
    return out


def figure(rows, fitted, path):
    laws = sorted({r["law"] for r in rows})
    fig, axes = plt.subplots(len(laws), len(FRONTS) + 1, figsize=(18, 4.2 * len(laws)), squeeze=False,
                             constrained_layout=True)
    for ax_row, law in zip(axes, laws):
        cells = sorted({r["h_m"] for r in rows if r["law"] == law}, reverse=True)
        for ax, (key, label) in zip(ax_row, FRONTS):
            for h in cells:
                mine = [r for r in rows if r["law"] == law and r["h_m"] == h]
                ax.plot([r["time_s"] for r in mine], [r[key] for r in mine], marker=".", label=mine[0]["cell"])
            ax.axhline(mine[0]["seam_depth_m"], color="0.5", ls="--", lw=0.8)
            ax.set_title(f"{law.replace('_', ' ')}: {label}", fontsize=9)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("distance from the face [m]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        ax = ax_row[-1]
        mine = [s for s in fitted if s["law"] == law]
        h = np.array([s["h_m"] for s in mine])
        for key, label in FRONTS:
            name = key.removesuffix("_m")
            ax.loglog(h, [s[f"{name}_m_per_s"] for s in mine], marker="o",
                      label=f"{name}, a = {mine[0][f'{name}_exponent']:.2f}")
        ref = [s["damage_front_m_per_s"] for s in mine if np.isfinite(s["damage_front_m_per_s"])]
        if ref:
            ax.loglog(h, ref[0] * h[0] / h, color="0.5", ls=":", label="~ 1/h")
        ax.set_title(f"{law.replace('_', ' ')}: front speed, fitted from {FIT_FROM:g} s", fontsize=9)
        ax.set_xlabel("cell h [m]")
        ax.set_ylabel("speed [m/s]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", default="results/outburst_convergence")
    ap.add_argument("--out", default="cases/outburst/convergence")
    args = ap.parse_args()
    rows = []
    for d in sorted(glob.glob(os.path.join(args.runs, "*"))):
        m = RUN_NAME.match(os.path.basename(d))
        if not (m and os.path.isdir(d)):
            continue
        if not glob.glob(os.path.join(d, "particles_*.h5")):
            why = ""
            if os.path.exists(os.path.join(d, "run.json")):
                with open(os.path.join(d, "run.json")) as f:
                    # A refusal names the scene's file and key first; the reason is what a reader needs.
                    why = json.load(f).get("failure", "").split("': ")[-1].split(";")[0]
            print(f"{d}: no output, skipped" + (f": {why}" if why else ""), file=sys.stderr)
            continue
        try:
            rows += measure(d, m.group(1), f"{m.group(2)}/{m.group(3)} m")
        except (OSError, KeyError, ValueError, IndexError) as e:
            print(f"{d}: cannot be read, skipped: {e}", file=sys.stderr)
    if not rows:
        sys.exit(f"no run with output in {args.runs}")
    fitted = speeds(rows)
    os.makedirs(args.out, exist_ok=True)
    write_rows(os.path.join(args.out, "front.csv"), rows)
    write_rows(os.path.join(args.out, "front_speeds.csv"), fitted)
    figure(rows, fitted, os.path.join(args.out, "front.png"))
    print("law         cell    cell ratio" + "".join(f"{k.removesuffix('_m'):>26}" for k, _ in FRONTS)
          + "   [m/s, ratio to coarser]")
    for s in fitted:
        print(f"{s['law']:<11} {s['cell']:<7} {s['cell_ratio']:>10.2f}" + "".join(
            f"{s[k.removesuffix('_m') + '_m_per_s']:>18.3g} ({s[k.removesuffix('_m') + '_ratio']:.2f})" for k, _ in FRONTS))
    for law in sorted({s["law"] for s in fitted}):
        s = next(s for s in fitted if s["law"] == law)
        print(f"{law}: a = " + ", ".join(f"{k.removesuffix('_m')} {s[k.removesuffix('_m') + '_exponent']:.2f}"
                                         for k, _ in FRONTS))


if __name__ == "__main__":
    main()
