"""Accuracy against wall time for one scene: sweep solver knobs, measure each
run's error, and show which knob buys accuracy cheapest.

usage: python3 -m cases.study STUDY.toml [--out DIR] [--jobs N] [--threads T] [--build build] [--check]

STUDY.toml names the scene, the program, a measure module and the knobs:

    scene = "terzaghi.toml"          # beside STUDY.toml
    program = "outburst"             # seepage-fe, mpm-solid, outburst or a path from here
                                     # (optional: the one the scene's solvers call for; one given
                                     # by path takes SCENE -q -o DIR --overwrite --set KEY=VALUE...)
    measure = "measure.py"           # beside STUDY.toml, see below (optional)
    set = ['scene.end_time="0.3 s"'] # overrides for every run (optional)
    combine = false                  # true: every combination; false: one knob at a time

    [[knobs]]
    name = "mpm_cell_size"           # a knob of KNOBS below ...
    values = ["0.1 m", "0.05 m", "0.025 m"]
    [[knobs]]
    key = "mpm.materials[0].youngs_modulus"  # ... or any scene key, named by `label`
    label = "stiffness"
    values = ['"10 MPa"', '"20 MPa"']

    [reference]                      # without an analytic solution: a much finer run
    mpm_cell_size = "0.0125 m"

The measure module defines errors(run_dir) -> {name: error} where an analytic
solution exists, or else quantities(run_dir) -> {name: value}, compared with
the reference run's (relative error; a value may be an array, a field on a
mesh all runs share, compared by its RMS difference over the reference's
largest magnitude). Without one, cases/generic_measure.py
compares mean and largest pressure and displacement with the reference's: any
scene can be studied given a [reference]. A run's error is the largest of its
named errors. Runs go side by side, `jobs` at a time with `threads` OpenMP
threads each (jobs x threads never exceeds the cores). Writes DIR/study.csv,
DIR/study.md and DIR/study.png (error against wall time, Pareto front marked),
and prints (and writes to DIR/study_orders.csv) each numeric knob's measured order: the slope of log error against
log value and against log wall time, with R^2 of the fit.
"""
import argparse
import concurrent.futures
import csv
import importlib
import importlib.util
import itertools
import math
import os
import subprocess
import sys
import tomllib

import numpy as np

from . import units
from .runs import REFUSED, run_one, write_rows


class StudyError(Exception):
    pass


# name: (scene key, what it is). Keys with [*] apply to every entry of that
# array. The words a choice takes are the program's (PROGRAM SCENE --explain
# --format json lists them), and a run with a word it lacks is refused there.
KNOBS = {
    "mpm_cell_size": ("mpm.grid.cell_size", "MPM grid spacing (a length)"),
    "particles_per_cell": ("mpm.bodies[*].particles_per_cell", "n for n x n particles per cell"),
    "shape": ("mpm.shape", "MPM shape functions"),
    "update_scheme": ("mpm.scheme", "when the MPM updates stresses"),
    "transfer": ("mpm.transfer", "particle-grid velocity transfer"),
    "courant": ("mpm.courant", "MPM Courant number"),
    "seepage_cells": ("seepage.mesh.cells", "structured seepage mesh cells [nx, ny]"),
    "seepage_time_step": ("seepage.time_step", "seepage (first) time step"),
    "seepage_time_scheme": ("seepage.time_scheme", "seepage time integration"),
    "newton_tolerance": ("seepage.tolerance", "seepage nonlinear tolerance"),
    "coupling_scheme": ("coupling", '"explicit", "explicit_fixed_stress", or an acceleration of the implicit scheme'),
    "window": ("coupling.window", "coupling window"),
    "coupling_tolerance": ("coupling.tolerance", "sub-iteration tolerance"),
}

def numeric(value):
    """The number a knob value stands for (the product, for cells [nx, ny]); None if categorical."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value):
        return float(np.prod(value))
    if isinstance(value, str):
        try:
            return float(units.si(value))
        except ValueError:
            return None
    return None


def short(value):
    """A knob value as a person would write it (0.333 m, not 0.3333333333333333 m)."""
    parts = units.split(value) if isinstance(value, str) else None
    if parts:
        return f"{parts[0]:.3g} {parts[1]}".strip()
    return str(value)


def toml_value(value):
    if isinstance(value, str):
        return value if value.startswith('"') else '"' + value + '"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return repr(value)


def count_entries(scene, dotted):
    node = scene
    for part in dotted.split("."):
        node = node.get(part, {}) if isinstance(node, dict) else {}
    return len(node) if isinstance(node, list) else 0


class Knob:
    def __init__(self, table, where, scene):
        if "name" in table:
            name = table["name"]
            if name not in KNOBS:
                raise StudyError(f"{where}: unknown knob \"{name}\"; known knobs: {', '.join(KNOBS)} "
                                 "(or give `key` = a scene key and `label`)")
            self.label, self.key = name, KNOBS[name][0]
        elif "key" in table:
            self.key = table["key"]
            self.label = table.get("label", self.key)
        else:
            raise StudyError(f"{where}: a knob needs `name` (one of {', '.join(KNOBS)}) or `key`")
        values = table.get("values")
        if not isinstance(values, list) or not values:
            raise StudyError(f"{where}: `values` must be a non-empty list")
        self.values = values
        self.scene = scene

    def overrides(self, value):
        if self.label == "coupling_scheme":
            if value == "explicit":
                return ['coupling.scheme="explicit"']
            if value == "explicit_fixed_stress":
                return ['coupling.scheme="explicit"', "coupling.fixed_stress=true"]
            if value == "one_way":
                raise StudyError("coupling_scheme: \"one_way\" sends nothing back, so it has no error to "
                                 "compare; vary the scene key coupling.scheme for it")
            return ['coupling.scheme="implicit"', f'coupling.acceleration="{value}"']
        if "[*]" in self.key:
            array, rest = self.key.split("[*]")
            n = count_entries(self.scene, array)
            if n == 0:
                raise StudyError(f"{self.label}: the scene has no [[{array}]] entries")
            return [f"{array}[{i}]{rest}={toml_value(value)}" for i in range(n)]
        return [f"{self.key}={toml_value(value)}"]


CASES = os.path.dirname(os.path.abspath(__file__))


def load_measure(path):
    """A measure module from its file. One inside this package is imported by
    its module name, so that its package imports resolve; one elsewhere (a
    user's own, a test's) is loaded from its file alone."""
    path = os.path.abspath(path)
    if os.path.commonpath([path, CASES]) == CASES:
        inner = os.path.splitext(os.path.relpath(path, CASES))[0]
        return importlib.import_module(".".join([__package__] + inner.split(os.sep)))
    module_spec = importlib.util.spec_from_file_location(os.path.splitext(os.path.basename(path))[0], path)
    if module_spec is None:
        raise StudyError(f"measure: {path} is not a Python module")
    measure = importlib.util.module_from_spec(module_spec)
    module_spec.loader.exec_module(measure)
    return measure


def load_study(path):
    try:
        with open(path, "rb") as f:
            spec = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise StudyError(f"{path}: {e}")
    here = os.path.dirname(os.path.abspath(path))
    for key in ("scene", "knobs"):
        if key not in spec:
            raise StudyError(f"{path}: missing `{key}`")
    unknown = set(spec) - {"scene", "program", "measure", "knobs", "set", "combine", "reference"}
    if unknown:
        raise StudyError(f"{path}: unknown key(s) {', '.join(sorted(unknown))}")
    scene_path = os.path.join(here, spec["scene"])
    try:
        with open(scene_path, "rb") as f:
            scene = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise StudyError(f"{path}: scene: {e}")
    knobs = [Knob(t, f"{path}: knobs[{i}]", scene) for i, t in enumerate(spec["knobs"])]
    spec_ref = spec.get("reference", {})
    names = {k.label for k in knobs}
    for name in spec_ref:
        if name not in names:
            raise StudyError(f"{path}: reference.{name} is not one of the knobs ({', '.join(sorted(names))})")
    measure_path = os.path.join(here, spec.get("measure", os.path.join(CASES, "generic_measure.py")))
    if not os.path.isfile(measure_path):
        raise StudyError(f"{path}: measure: no module {measure_path}")
    measure = load_measure(measure_path)
    if not hasattr(measure, "errors") and not hasattr(measure, "quantities"):
        raise StudyError(f"{measure_path}: defines neither errors(run_dir) nor quantities(run_dir)")
    if not hasattr(measure, "errors") and not spec_ref:
        raise StudyError(f"{path}: without an analytic errors(run_dir) the study needs a [reference] run")
    solvers = tuple(sorted(scene.get("scene", {}).get("solvers", [])))
    default_program = {("mpm",): "mpm-solid", ("seepage",): "seepage-fe", ("mpm", "seepage"): "outburst"}
    if "program" not in spec and solvers not in default_program:
        raise StudyError(f"{path}: name the `program` (the scene's solvers {list(solvers)} call for none)")
    return {"scene": scene_path, "program": spec.get("program", default_program.get(solvers)), "measure": measure, "knobs": knobs,
            "set": list(spec.get("set", [])), "combine": bool(spec.get("combine", False)), "reference": spec_ref}


def program_path(program, build, study_dir):
    if os.sep in program:
        return os.path.join(study_dir, program)
    where = {"seepage-fe": "seepage_fe", "mpm-solid": "mpm_solid", "outburst": "coupler"}
    if program not in where:
        raise StudyError(f"program \"{program}\": expected seepage-fe, mpm-solid, outburst or a path")
    return os.path.join(build, where[program], program)


def fit(x, y):
    """Slope of log y against log x and R^2; None with fewer than 3 usable points."""
    pts = [(math.log(a), math.log(b)) for a, b in zip(x, y) if a > 0 and b > 0 and math.isfinite(b)]
    if len(pts) < 3:
        return None
    lx, ly = np.array(pts).T
    slope, intercept = np.polyfit(lx, ly, 1)
    residual = ly - (slope * lx + intercept)
    total = ((ly - ly.mean()) ** 2).sum()
    return float(slope), float(1 - (residual ** 2).sum() / total) if total > 0 else 1.0


def difference(value, reference):
    """Relative error of a quantity: of a number, or RMS of a field over the reference's largest magnitude."""
    value, reference = np.asarray(value, dtype=float), np.asarray(reference, dtype=float)
    if value.shape != reference.shape:
        raise StudyError(f"a field of {value.size} values against the reference's {reference.size}: fields compare "
                         "only on a mesh every run shares")
    scale = max(float(np.abs(reference).max()), 1e-300)
    return float(np.sqrt(np.mean((value - reference) ** 2)) / scale) if value.ndim else abs(float(value - reference)) / scale


def sub_iterations(run_dir):
    """Mean coupling sub-iterations per window of a coupled run, or None."""
    path = os.path.join(run_dir, "coupling.csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        counts = [int(r["iterations"]) for r in csv.DictReader(f)]
    return sum(counts) / len(counts) if counts else None


def pareto(rows):
    """Indices of runs no other run beats in both wall time and error."""
    ok = [i for i, r in enumerate(rows) if math.isfinite(r["error"])]
    front = []
    for i in ok:
        if not any(rows[j]["wall_s"] <= rows[i]["wall_s"] and rows[j]["error"] <= rows[i]["error"] and
                   (rows[j]["wall_s"] < rows[i]["wall_s"] or rows[j]["error"] < rows[i]["error"]) for j in ok):
            front.append(i)
    return sorted(front, key=lambda i: rows[i]["wall_s"])


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study")
    ap.add_argument("--out", help="output folder (default: results/study_<study folder name>)")
    ap.add_argument("--jobs", type=int, help="runs side by side (default: cores / threads)")
    ap.add_argument("--threads", type=int, default=1, help="OpenMP threads per run (default 1)")
    ap.add_argument("--build", default="build", help="the build folder holding the programs")
    ap.add_argument("--check", action="store_true", help="validate the study and every run's scene, run nothing")
    return ap.parse_args()


def share_cores(jobs, threads):
    """Runs side by side and threads per run, jobs x threads within the cores."""
    cores = os.cpu_count() or 1
    threads = max(1, min(threads, cores))
    jobs = jobs or max(1, cores // threads)
    if jobs * threads > cores:
        raise StudyError(f"{jobs} jobs x {threads} threads would oversubscribe {cores} cores")
    return jobs, threads


def plan(study):
    """The runs as (tag, setting, overrides): each knob alone around the scene's
    values, or every combination; the reference run first."""
    knobs = study["knobs"]
    if study["combine"]:
        labels = [k.label for k in knobs]
        settings = [dict(zip(labels, combo)) for combo in itertools.product(*[k.values for k in knobs])]
    else:
        settings = [{k.label: v} for k in knobs for v in k.values]

    def overrides(setting):
        o = list(study["set"])
        for k in knobs:
            if k.label in setting:
                o += k.overrides(setting[k.label])
        return o
    planned = [(f"run_{i:03d}", s, overrides(s)) for i, s in enumerate(settings)]
    if study["reference"]:
        planned.insert(0, ("reference", study["reference"], overrides(study["reference"])))
    return planned


def check(program, study, planned, name):
    """Validates every run's scene with the program's --check; prints what it refuses."""
    refused = 0
    for tag, setting, o in planned:
        command = [program, study["scene"], "--check"] + [x for v in o for x in ("--set", v)]
        done = subprocess.run(command, capture_output=True, text=True)
        lines = (done.stderr or done.stdout).strip().splitlines()
        # Exit code 4: a valid setting the program refuses as unstable, a
        # result of the sweep (the reference must run, though).
        if done.returncode == REFUSED and tag != "reference":
            refused += 1
            print(f"study: {tag} {setting}: refused: {lines[-1] if lines else ''}")
        elif done.returncode != 0:
            raise StudyError(f"{name}: {tag} {setting}: {lines[-1] if lines else 'invalid'}")
    print(f"study: {name}: {len(planned)} runs, every scene valid"
          + (f" ({refused} refused as unstable)" if refused else ""))


def run_all(program, study, planned, out, jobs, threads):
    """Runs the plan side by side; each tag's wall time and failure note."""
    print(f"study: {len(planned)} runs of {study['scene']}, {jobs} at a time with {threads} thread(s) each",
          flush=True)
    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(run_one, program, study["scene"], o, os.path.join(out, tag), threads): (tag, s)
                   for tag, s, o in planned}
        for f in concurrent.futures.as_completed(futures):
            tag, setting = futures[f]
            wall, note = f.result()
            results[tag] = (wall, note)
            print(f"  {tag} {setting}: {wall:.1f} s {note}", flush=True)
    return results


def measure_runs(study, planned, results, out):
    """A row per run (the reference aside): its knob values, wall time, error and
    each named error, and its sub-iterations if coupled."""
    measure, knobs = study["measure"], study["knobs"]
    reference = None
    if study["reference"]:
        wall, note = results["reference"]
        if note:
            raise StudyError(f"the reference run failed: {note}")
        reference = measure.quantities(os.path.join(out, "reference"))
    rows = []
    for tag, setting, _ in planned:
        if tag == "reference":
            continue
        wall, note = results[tag]
        errors, iterations = {}, None
        if not note:
            directory = os.path.join(out, tag)
            iterations = sub_iterations(directory)
            try:
                if hasattr(measure, "errors"):
                    errors = measure.errors(directory)
                else:
                    q = measure.quantities(directory)
                    errors = {k: difference(q[k], v) for k, v in reference.items()}
            except StudyError as e:
                raise StudyError(f"{tag}: {e}") from e
        row = {"run": tag, **{k.label: setting.get(k.label, "") for k in knobs}, "wall_s": wall,
               "error": max(errors.values()) if errors else float("nan"), "note": note}
        if iterations is not None:
            row["sub_iterations"] = iterations
        row.update({f"error_{k}": v for k, v in errors.items()})
        rows.append(row)
    front = set(pareto(rows))
    for i, r in enumerate(rows):
        r["pareto"] = i in front
    return rows


def orders(knobs, rows, combine):
    """Each numeric knob's order: alone, or (combined) for each setting of the
    others. (label, (p, R^2) in value, (q, R^2) in wall time or None)."""
    found = []
    for k in knobs:
        others = [o for o in knobs if o is not k]
        if combine:
            groups = {}
            for r in rows:
                groups.setdefault(tuple(short(r[o.label]) for o in others), []).append(r)
        else:
            groups = {(): [r for r in rows if r[k.label] != "" and all(r[o.label] == "" for o in others)]}
        for key, mine in groups.items():
            values = [numeric(r[k.label]) for r in mine]
            if None in values or len(set(values)) < 3:
                continue
            by_value = fit(values, [r["error"] for r in mine])
            by_time = fit([r["wall_s"] for r in mine], [r["error"] for r in mine])
            label = k.label + (" (" + ", ".join(f"{o.label} {v}" for o, v in zip(others, key)) + ")" if key else "")
            if by_value:
                found.append((label, by_value, by_time))
    return found


def table(study, rows, found, jobs, threads):
    """study.md's lines: a row per run, then the orders."""
    knobs, measure = study["knobs"], study["measure"]
    coupled = any("sub_iterations" in r for r in rows)
    lines = [f"# Study: `{os.path.relpath(study['scene'])}`", "",
             f"Error: {'against the analytic solution' if hasattr(measure, 'errors') else 'relative to the reference run'} "
             f"({', '.join(sorted({c[6:] for r in rows for c in r if c.startswith('error_')}))}); "
             f"{jobs} run(s) at a time, {threads} thread(s) each. * marks the Pareto front (no run both faster "
             "and more accurate).", "",
             "| " + " | ".join(k.label for k in knobs) + (" | sub-iterations / window" if coupled else "") +
             " | wall [s] | error | |",
             "|" + "---|" * (len(knobs) + 3 + coupled)]
    for r in rows:
        cells = [short(r[k.label]) if r[k.label] != "" else "-" for k in knobs]
        if coupled:
            cells.append(f"{r['sub_iterations']:.2f}" if "sub_iterations" in r else "-")
        error = f"{r['error']:.3e}" if math.isfinite(r["error"]) else r["note"][:60]
        lines.append("| " + " | ".join(cells) + f" | {r['wall_s']:.2f} | {error} | {'*' if r['pareto'] else ''} |")
    if found:
        lines += ["", "| knob | error ~ value^p: p (R^2) | error ~ wall^q: q (R^2) |", "|---|---|---|"]
        for label, (p, r2), by_time in found:
            t = f"{by_time[0]:.2f} ({by_time[1]:.3f})" if by_time else "-"
            lines.append(f"| {label} | {p:.2f} ({r2:.3f}) | {t} |")
    return lines


def write_orders(path, found):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["knob", "order_in_value", "r2_value", "order_in_wall_time", "r2_wall_time"])
        for label, (p, r2), by_time in found:
            w.writerow([label, p, r2, by_time[0] if by_time else "", by_time[1] if by_time else ""])


def plot(study, rows, path):
    """Error against wall time, each knob's runs (or every run, combined) and the Pareto front."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    if study["combine"]:
        ok = [r for r in rows if math.isfinite(r["error"])]
        ax.plot([r["wall_s"] for r in ok], [r["error"] for r in ok], "o", label="runs")
    else:
        for k in study["knobs"]:
            mine = [r for r in rows if r[k.label] != "" and math.isfinite(r["error"])]
            ax.plot([r["wall_s"] for r in mine], [r["error"] for r in mine], "o-", label=k.label)
            for r in mine:
                ax.annotate(short(r[k.label]), (r["wall_s"], r["error"]), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
    front = sorted((r for r in rows if r["pareto"]), key=lambda r: r["wall_s"])
    ax.step([r["wall_s"] for r in front], [r["error"] for r in front], "k--", where="post", lw=1,
            label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("error")
    ax.set_title(os.path.basename(study["scene"]))
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    args = parse_args()
    try:
        study = load_study(args.study)
        program = program_path(study["program"], args.build, os.path.dirname(os.path.abspath(args.study)))
        if not os.access(program, os.X_OK):
            raise StudyError(f"program {program} not found: build first, or pass --build")
        jobs, threads = share_cores(args.jobs, args.threads)
        planned = plan(study)
        if args.check:
            check(program, study, planned, args.study)
            return
        name = os.path.basename(os.path.dirname(os.path.abspath(args.study)))
        out = args.out or os.path.join("results", f"study_{name}")
        os.makedirs(out, exist_ok=True)
        results = run_all(program, study, planned, out, jobs, threads)
        rows = measure_runs(study, planned, results, out)
    except StudyError as e:
        sys.exit(f"study: {e}")
    write_rows(os.path.join(out, "study.csv"), rows)
    found = orders(study["knobs"], rows, study["combine"])
    lines = table(study, rows, found, jobs, threads)
    with open(os.path.join(out, "study.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    write_orders(os.path.join(out, "study_orders.csv"), found)
    print("\n".join(lines))
    plot(study, rows, os.path.join(out, "study.png"))
    print(f"study: {out}/study.csv, study.md, study.png")


if __name__ == "__main__":
    main()
