"""An ensemble of the outburst case over heterogeneous coal: one run per seed of
the Weibull draw, side by side, and each headline number's mean, spread and
95 % confidence interval.

usage: python3 -m cases.outburst.ensemble [--outburst build/coupler/outburst] [--out results/outburst_ensemble]
                                          [--seeds 8] [--homogeneity 3] [--end-time "1 s"] [--jobs J]
                                          [--set KEY=VALUE ...] [--sweep KEY --values V1 V2 ...] [--resume]

Each run is the shipped case with mpm.materials[0].heterogeneity = {
homogeneity_index = M, seed = k} for k = 1..N (docs/theory/materials.md,
heterogeneous coal), plus the --set overrides. J runs go side by side with
cores / J threads each, so jobs x threads never exceed the cores. Writes
OUT/ensemble.csv (a row per seed), OUT/ensemble.md (the statistics) and
OUT/ensemble.png (each quantity's runs, mean and interval). With --sweep, one
ensemble runs at each value of KEY (OUT/value_NN_VALUE/), and OUT/sweep.md and
OUT/sweep.png set each quantity's mean and interval against the values: a
knob's effect beside the spread the coal alone gives. A finished run keeps its
row in its folder (row.json); --resume reads it instead of running it again
when the overrides are the same.
"""
import argparse
import concurrent.futures
import json
import math
import os
import re
import sys

import numpy as np
from scipy import stats

from ..runs import run_one, write_rows
from .headline import headline

HERE = os.path.dirname(os.path.abspath(__file__))

# The headline numbers the statistics cover, with their labels.
QUANTITIES = [
    ("centre_m_per_s", "centre tracer's peak speed [m/s]"),
    ("farthest_m", "farthest coal from the face [m]"),
    ("ejected_fraction", "coal ejected (share)"),
    ("fully_damaged_fraction", "fully damaged coal (share)"),
    ("gas_released_m3_per_m", "gas released [m3/m]"),
]


def one_seed(program, overrides, directory, threads, resume):
    """Runs one member (or keeps its earlier row); returns its row."""
    kept = os.path.join(directory, "row.json")
    if resume and os.path.exists(kept):
        with open(kept) as f:
            earlier = json.load(f)
        # Only a finished run is kept: one that failed (or was killed) runs again.
        if earlier["overrides"] == overrides and "failure" not in earlier["row"]:
            return earlier["row"]
    wall, failure = run_one(program, os.path.join(HERE, "outburst.toml"), overrides, directory, threads)
    row = {"wall_s": wall}
    if failure:
        row["failure"] = failure.split("] ")[-1]
    else:
        row.update(headline(directory))
    with open(kept, "w") as f:
        json.dump({"overrides": overrides, "row": row}, f)
    return row


def summary(values):
    """Mean, sample standard deviation and the 95 % interval of the mean (Student t)."""
    v = np.asarray(values, dtype=float)
    mean = float(v.mean())
    if len(v) < 2:
        return mean, math.nan, math.nan
    sd = float(v.std(ddof=1))
    return mean, sd, float(stats.t.ppf(0.975, len(v) - 1) * sd / math.sqrt(len(v)))


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = [r for r in rows if "failure" not in r]
    fig, axes = plt.subplots(1, len(QUANTITIES), figsize=(3.2 * len(QUANTITIES), 3.4))
    for ax, (key, label) in zip(axes, QUANTITIES):
        values = [r[key] for r in ok]
        mean, _, half = summary(values)
        ax.plot(np.zeros(len(values)), values, "o", alpha=0.6, label="runs")
        if math.isfinite(half):
            ax.errorbar([0.3], [mean], yerr=[half], fmt="s", color="k", capsize=4, label="mean, 95 % CI")
        ax.set_xlim(-0.5, 0.8)
        ax.set_xticks([])
        ax.set_title(label, fontsize=9)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"outburst ensemble over heterogeneous coal: {len(ok)} seeds")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def run_ensemble(args, overrides, out, jobs, threads):
    """Runs (or resumes) one ensemble into out, writes its CSV, table and plot; returns its rows."""
    os.makedirs(out, exist_ok=True)
    members = []
    for seed in range(1, args.seeds + 1):
        member = [f'scene.end_time="{args.end_time}"',
                  f"mpm.materials[0].heterogeneity={{homogeneity_index={args.homogeneity:g}, seed={seed}}}"]
        members.append((seed, member + overrides, os.path.join(out, f"seed_{seed:03d}")))
    rows = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(one_seed, args.outburst, o, d, threads, args.resume): s for s, o, d in members}
        for done in concurrent.futures.as_completed(futures):
            seed = futures[done]
            rows[seed] = {"seed": seed, **done.result()}
            state = rows[seed].get("failure", "done")
            print(f"{out}: seed {seed}: {state} ({rows[seed]['wall_s']:.0f} s)", flush=True)
    rows = [rows[s] for s in sorted(rows)]
    write_rows(os.path.join(out, "ensemble.csv"), rows)
    ok = [r for r in rows if "failure" not in r]
    lines = ["# Outburst ensemble over heterogeneous coal", "",
             f"{len(ok)} of {len(rows)} seeds finished; homogeneity index {args.homogeneity:g}, "
             f"{args.end_time} simulated; overrides: {', '.join(overrides) or 'none'}.", "",
             "| quantity | mean | standard deviation | 95 % interval of the mean | min | max |",
             "|---|---|---|---|---|---|"]
    for key, label in QUANTITIES:
        values = [r[key] for r in ok]
        if not values:
            continue
        mean, sd, half = summary(values)
        lines.append(f"| {label} | {mean:.4g} | {sd:.3g} | +- {half:.3g} | {min(values):.4g} | {max(values):.4g} |")
    for r in rows:
        if "failure" in r:
            lines.append(f"\nseed {r['seed']} failed: {r['failure']}")
    with open(os.path.join(out, "ensemble.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    if ok:
        plot(rows, os.path.join(out, "ensemble.png"))
    print("\n".join(lines), flush=True)
    return rows


def sweep_report(key, values, ensembles, out):
    """Each quantity's mean and interval at each value of the swept key: sweep.md and sweep.png."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    lines = [f"# Outburst ensembles against {key}", "",
             "Mean +- the 95 % interval of the mean. The same seeds run at every value, so the coals are "
             "paired (unless the key changes how particles are created).", "",
             "| quantity | " + " | ".join(f"{key} = {v}" for v in values) + " |",
             "|---|" + "---|" * len(values)]
    fig, axes = plt.subplots(1, len(QUANTITIES), figsize=(3.2 * len(QUANTITIES), 3.4))
    for ax, (q, label) in zip(axes, QUANTITIES):
        cells, means, halves = [], [], []
        for rows in ensembles:
            finished = [r[q] for r in rows if "failure" not in r]
            mean, _, half = summary(finished) if finished else (math.nan, math.nan, math.nan)
            cells.append(f"{mean:.4g} +- {half:.2g} ({len(finished)} seeds)")
            means.append(mean)
            halves.append(half)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
        # A value with fewer than two finished seeds has no interval: drawn hollow, no bar.
        has = [math.isfinite(h) for h in halves]
        ax.errorbar([k for k in range(len(values)) if has[k]], [m for m, h in zip(means, has) if h],
                    yerr=[x for x in halves if math.isfinite(x)], fmt="o", capsize=4)
        ax.plot(range(len(values)), means, "-", color="C0")
        ax.plot([k for k in range(len(values)) if not has[k]], [m for m, h in zip(means, has) if not h], "o",
                mfc="none", color="C0")
        ax.set_xticks(range(len(values)), values, rotation=30, fontsize=8)
        ax.set_title(label, fontsize=9)
    fig.suptitle(f"outburst ensembles against {key} (mean, 95 % interval of the mean)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "sweep.png"), dpi=120)
    with open(os.path.join(out, "sweep.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outburst", default="build/coupler/outburst")
    ap.add_argument("--out", default="results/outburst_ensemble")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--homogeneity", type=float, default=3.0)
    ap.add_argument("--end-time", default="1 s")
    ap.add_argument("--jobs", type=int, default=0, help="runs side by side (0: one per core)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="another override for every run")
    ap.add_argument("--sweep", metavar="KEY", help="a scene key to run an ensemble at each of --values")
    ap.add_argument("--values", nargs="+", default=[], metavar="VALUE", help="the swept key's values (TOML)")
    ap.add_argument("--resume", action="store_true", help="keep the rows an earlier ensemble finished")
    args = ap.parse_args()
    if args.seeds < 1:
        ap.error("--seeds must be at least 1")
    if args.homogeneity < 1:
        ap.error("--homogeneity must be at least 1 (the Weibull shape of the strengths)")
    if bool(args.sweep) != bool(args.values):
        ap.error("--sweep KEY and --values go together")
    cores = os.cpu_count() or 1
    jobs = min(args.jobs or cores, cores, args.seeds)
    if jobs < 1:
        ap.error("--jobs must be at least 1")
    threads = max(1, cores // jobs)
    print(f"ensemble: {args.seeds} seeds, {jobs} side by side with {threads} thread(s) each", flush=True)
    if not args.sweep:
        rows = run_ensemble(args, args.set, args.out, jobs, threads)
        if not any("failure" not in r for r in rows):
            sys.exit("ensemble: no seed finished")
        return
    # Folder names without the brackets and quotes of keys and values (glob reads brackets).
    ensembles = [run_ensemble(args, args.set + [f"{args.sweep}={v}"],
                              os.path.join(args.out, f"value_{k:02d}_" + re.sub(r"[^\w.+-]+", "_", v)), jobs, threads)
                 for k, v in enumerate(args.values)]
    sweep_report(args.sweep, args.values, ensembles, args.out)


if __name__ == "__main__":
    main()
