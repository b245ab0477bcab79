"""Convergence of the outburst with resolution: the MPM grid and the seepage
mesh refined together (2 x 2 particles per cell throughout), under the paper's
local damage law and under a crack band with the fracture energy of
outburst-prone coal.

usage: python3 -m cases.outburst.convergence [--outburst build/coupler/outburst] [--out results/outburst_convergence]
                                              [--cells 1/2 1/3 1/4 1/6 1/8] [--laws local crack_band]
                                              [--end-time "1 s"] [--at 0.5 1] [--resume | --measure-only]
                                              [--seeds N [--homogeneity 3] [--jobs J]] [--set KEY=VALUE ...]
writes OUT/convergence.csv (a row per law, cell and time measured at),
OUT/convergence.md (the headline numbers and the change between the two finest
cells) and OUT/convergence.png; one run at a time, each on every core (the
finest, 1/8 m, takes 20-25 minutes to 1 s on 2 cores; the whole study about an
hour and a half). Each finished run is kept in its folder (run.json): --resume
measures those instead of running them again, --measure-only runs nothing.
With --seeds N the coal is heterogeneous (docs/theory/materials.md,
heterogeneous coal): N seeds at each cell, J side by side, and OUT/convergence_ensemble.csv
and .md give each quantity's mean and 95 % interval by cell, and whether the
two finest cells' means differ (Welch's t-test at 5 %).
"""
import argparse
import concurrent.futures
import json
import os
from fractions import Fraction

import numpy as np

from ..runs import run_one, write_rows
from .headline import headline
from .laws import SHIPPED, crack_band_scene, seam_mesh
from .report import Run


LAWS = ["local", "crack_band"]
# The quantities compared, with their labels.
QUANTITIES = [
    ("centre_m_per_s", "centre peak speed [m/s]"),
    ("farthest_m", "run-out [m]"),
    ("ejected_fraction", "coal ejected"),
    ("fully_damaged_fraction", "fully damaged"),
    ("gas_released_m3_per_m", "gas released [m3/m]"),
    ("cavity_m2_per_m", "cavity [m2/m]"),
    ("cavity_depth_m", "cavity depth [m]"),
    ("cavity_mouth_m", "cavity mouth [m]"),
]


def scene_for(law, out):
    """outburst.toml under a damage law: the shipped file, or a copy with a
    crack band of outburst-prone coal's G_f (laws.py)."""
    return SHIPPED if law == "local" else crack_band_scene(out)


def table(rows, law, time):
    """The markdown table of a law's rows measured at `time` [s]."""
    mine = [r for r in rows if r["law"] == law and (r.get("failure") or r["time_s"] == time)]
    done = [r for r in mine if not r.get("failure")]
    lines = [f"### {law.replace('_', ' ')}, t = {time:g} s", "",
             "| cell [m] | particles | " + " | ".join(label for _, label in QUANTITIES) + " | wall [s] |",
             "|---|---|" + "---|" * len(QUANTITIES) + "---|"]
    for r in mine:
        if r.get("failure"):
            # A refusal names the scene's file and key first; the reason is what a reader needs.
            reason = r["failure"].split("': ")[-1]
            lines.append(f"| {r['cell']} | | {reason} |" + " |" * len(QUANTITIES))
            continue
        lines.append(f"| {r['cell']} | {r['particles']:.0f} | " +
                     " | ".join(f"{r[k]:.3g}" for k, _ in QUANTITIES) + f" | {r['wall_s']:.0f} |")
    if len(done) >= 2:
        a, b = done[-2], done[-1]
        change = lambda k: f"{abs(b[k] - a[k]) / abs(b[k]):.0%}" if b[k] else "-"
        lines.append(f"| change {a['cell']} to {b['cell']} | | " + " | ".join(change(k) for k, _ in QUANTITIES) + " | |")
    return lines


def figure(rows, times, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, (len(QUANTITIES) + 1) // 2, figsize=(16, 6.5), constrained_layout=True)
    for ax, (key, label) in zip(axes.ravel(), QUANTITIES):
        for law, marker in zip(LAWS, "os"):
            for time, style in zip(times, ("--", "-", ":")):
                done = [r for r in rows if r["law"] == law and not r.get("failure") and r["time_s"] == time]
                if done:
                    ax.plot([float(Fraction(r["cell"].split()[0])) for r in done], [r[key] for r in done],
                            marker=marker, linestyle=style, label=f"{law.replace('_', ' ')}, t = {time:g} s")
        ax.set_xlabel("cell [m] (MPM grid and seepage mesh)")
        ax.set_title(label, fontsize=10)
        ax.invert_xaxis()
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Outburst: headline numbers as the grid is refined")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write(rows, laws, times, out):
    """convergence.md and convergence.png from the study's rows."""
    lines = ["# Outburst: convergence with resolution", "",
             "MPM cells and seepage elements of the edge given, 2 x 2 particles per cell, measured at each time "
             "(the jet reaches the 25 m tunnel's end before 1 s on the finer grids: run-out and ejected coal are "
             "then capped); the change between the two finest cells relative to the finest. Most quantities do "
             "not approach a limit monotonically, so no order is fitted.", ""]
    for time in times:
        for law in laws:
            lines += table(rows, law, time) + [""]
    with open(os.path.join(out, "convergence.md"), "w") as f:
        f.write("\n".join(lines))
    figure(rows, times, os.path.join(out, "convergence.png"))
    return lines


def kept_or_run(args, law, scene, overrides, run_dir, label, threads):
    """One run of the study: the one kept in run_dir (with --resume or
    --measure-only, if made with the same scene and overrides), or a new one;
    None if --measure-only finds none."""
    os.makedirs(run_dir, exist_ok=True)
    kept = os.path.join(run_dir, "run.json")
    if (args.resume or args.measure_only) and os.path.exists(kept):
        with open(kept) as f:
            run = json.load(f)
        if run["overrides"] == overrides and run["law"] == law and run.get("scene") == scene:
            print(f"{law}, {label}: kept from {run_dir}", flush=True)
            return run
    if args.measure_only:
        return None
    wall, failure = run_one(args.outburst, scene, overrides, run_dir, threads)
    run = {"law": law, "scene": scene, "overrides": overrides, "wall_s": wall, "failure": failure}
    with open(kept, "w") as f:
        json.dump(run, f)
    return run


def measured(run, run_dir, row, times):
    """The rows of one run: one per time measured at, or its failure."""
    if run is None:
        return [row | {"failure": "not run (--measure-only)"}]
    row = row | {"wall_s": run["wall_s"]}
    if run["failure"]:
        return [row | {"failure": run["failure"]}]
    particles = len(Run(run_dir).particles(0)["points"])
    return [row | {"time_s": time, "particles": particles} | headline(run_dir, time) for time in times]


def ensemble_table(rows, law, time, homogeneity, failures=True, grain=None):
    """Markdown: each quantity's mean and 95 % interval over the seeds, by cell
    (coarsest first), and whether the two finest cells' means differ
    (Welch's t-test at 5 %: the seeds are independent draws at each cell)."""
    from scipy import stats
    from .ensemble import summary
    cells = sorted({r["cell"] for r in rows if r["law"] == law}, key=lambda c: -Fraction(c.split()[0]))
    draws = "a draw per particle" if grain is None else f"a draw per {grain:g} m grain"
    lines = [f"### {law.replace('_', ' ')}, heterogeneous coal (m = {homogeneity:g}, {draws}), t = {time:g} s", "",
             "| quantity | " + " | ".join(f"{c} (seeds)" for c in cells) +
             (" | two finest differ (Welch's t-test at 5 %) |" if len(cells) > 1 else " |"),
             "|---|" + "---|" * len(cells) + ("---|" if len(cells) > 1 else "")]
    for key, label in QUANTITIES:
        values = [[r[key] for r in rows if r["law"] == law and r["cell"] == c and not r.get("failure")
                   and r["time_s"] == time] for c in cells]
        line = f"| {label} | " + " | ".join(
            "-" if not v else f"{v[0]:.3g} (1)" if len(v) == 1 else
            "{:.3g} +- {:.2g} ({})".format(*(summary(v)[0::2] + (len(v),))) for v in values)
        if len(cells) > 1:
            a, b = values[-2], values[-1]
            if len(a) < 2 or len(b) < 2:
                line += " | - (fewer than two seeds)"
            elif np.std(a) == 0 and np.std(b) == 0:
                line += " | " + ("no" if a[0] == b[0] else "yes")
            else:
                p = stats.ttest_ind(a, b, equal_var=False).pvalue
                apart = abs(np.mean(a) - np.mean(b))
                share = f" ({100 * apart / abs(np.mean(b)):.1f} % of the finer's)" if np.mean(b) else ""
                line += f" | {'yes' if p < 0.05 else 'no'}: means {apart:.3g} apart{share}, p = {p:.2g}"
        lines.append(line + " |")
    if failures:
        for r in rows:
            if r["law"] == law and r.get("failure"):
                lines += ["", f"{r['cell']}, seed {int(r['seed'])}: {r['failure']}"]
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outburst", default="build/coupler/outburst")
    ap.add_argument("--out", default="results/outburst_convergence")
    ap.add_argument("--cells", nargs="+", default=["1/2", "1/3", "1/4", "1/6", "1/8"],
                    help="MPM cell and seepage element edges [m], as fractions, coarsest first")
    ap.add_argument("--laws", nargs="+", default=LAWS, choices=LAWS)
    ap.add_argument("--end-time", default="1 s")
    ap.add_argument("--at", nargs="+", type=float, default=[0.5, 1.0],
                    help="times [s] the headline numbers are measured at (multiples of 0.1 s, up to the end)")
    ap.add_argument("--seeds", type=int, default=0,
                    help="heterogeneous coal: an ensemble of this many seeds at each cell (0: uniform coal)")
    ap.add_argument("--homogeneity", type=float, default=3.0, help="the ensembles' Weibull shape m")
    ap.add_argument("--grain-size", type=Fraction,
                    help="side [m] of the squares of coal that share a draw (heterogeneity.grain_size), as a "
                         "fraction; without it each particle draws its own, and each cell another coal")
    ap.add_argument("--jobs", type=int, default=1, help="an ensemble's runs side by side (cores / jobs threads each)")
    ap.add_argument("--threads", type=int,
                    help="threads of each run (default: every core, shared out over an ensemble's jobs); two "
                         "studies of one cell each at --threads 1 run side by side without their threads "
                         "waiting on each other")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene override (as the programs' --set) for every run, after the study's own: "
                         "mpm.courant=0.19 runs each cell at another step; give such a study its own --out")
    ap.add_argument("--resume", action="store_true", help="keep the runs an earlier study finished")
    ap.add_argument("--measure-only", action="store_true",
                    help="run nothing: measure the runs an earlier study finished, and list the others as not run")
    args = ap.parse_args()
    if args.seeds < 0 or args.homogeneity < 1 or args.jobs < 1 or (args.threads is not None and args.threads < 1):
        ap.error("--seeds must be at least 0, --homogeneity, --jobs and --threads at least 1")
    if args.grain_size is not None and (args.grain_size <= 0 or not args.seeds):
        ap.error("--grain-size must be positive, and needs --seeds")
    os.makedirs(args.out, exist_ok=True)
    cells = [Fraction(c) for c in args.cells]
    cores = os.cpu_count() or 1
    jobs = min(args.jobs, cores, max(args.seeds, 1))
    threads = args.threads or max(1, cores // jobs)
    grain = "" if args.grain_size is None else f"_g{args.grain_size.numerator}_{args.grain_size.denominator}"
    rows = []
    for law in args.laws:
        scene = scene_for(law, args.out)
        for cell in cells:
            label = f"{cell} m"
            name = f"{law}_{cell.numerator}_{cell.denominator}"
            overrides = [f'scene.end_time="{args.end_time}"', f'mpm.grid.cell_size="{float(cell)!r} m"',
                         f'seepage.mesh.file="{seam_mesh(args.out, cell, f"seam_{cell.numerator}_{cell.denominator}.msh")}"', 'output.interval="0.1 s"'] + args.set
            # The overrides given with --set, so the CSV says what the run was.
            row = {"law": law, "cell": label} | ({"settings": " ".join(args.set)} if args.set else {})
            if not args.seeds:
                run_dir = os.path.join(args.out, name)
                rows += measured(kept_or_run(args, law, scene, overrides, run_dir, label, args.threads or cores), run_dir, row,
                                 args.at)
                print(f"{law}, {label}: {rows[-1]}", flush=True)
                continue
            # An ensemble at this cell: the same seeds at every cell (though
            # another cell draws another coal: the draw follows the particles).
            grain_key = "" if args.grain_size is None else f', grain_size="{float(args.grain_size)!r} m"'
            members = [(seed, os.path.join(args.out, f"{name}_m{args.homogeneity:g}{grain}_seed_{seed:03d}"),
                        overrides + [f"mpm.materials[0].heterogeneity={{homogeneity_index={args.homogeneity:g}, "
                                     f"seed={seed}{grain_key}}}"]) for seed in range(1, args.seeds + 1)]
            with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
                runs = list(pool.map(lambda m: kept_or_run(args, law, scene, m[2], m[1], f"{label}, seed {m[0]}",
                                                           threads), members))
            for (seed, run_dir, _), run in zip(members, runs):
                rows += measured(run, run_dir, row | {"seed": seed, "homogeneity": args.homogeneity,
                                                      "grain_size_m": "" if args.grain_size is None
                                                      else float(args.grain_size)}, args.at)
                print(f"{law}, {label}, seed {seed}: {rows[-1]}", flush=True)
    if not args.seeds:
        write_rows(os.path.join(args.out, "convergence.csv"), rows)
        print("\n".join(write(rows, args.laws, args.at, args.out)))
        return
    write_rows(os.path.join(args.out, f"convergence_ensemble{grain}.csv"), rows)
    lines = ["# Outburst: convergence with resolution over heterogeneous coal", "",
             f"An ensemble of {args.seeds} seeds at each cell: each quantity's mean +- the 95 % interval of the mean "
             "(Student t), with the number of seeds that finished.", ""]
    for k, time in enumerate(args.at):
        for law in args.laws:
            lines += ensemble_table(rows, law, time, args.homogeneity, failures=k == 0,
                                    grain=None if args.grain_size is None else float(args.grain_size)) + [""]
    with open(os.path.join(args.out, f"convergence_ensemble{grain}.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
