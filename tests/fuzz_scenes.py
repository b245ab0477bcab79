#!/usr/bin/python3
"""Fuzzing the programs with mutated shipped scenes: keys deleted or renamed,
signs flipped, values scaled by 1e-30..1e30 (and 1e+-300), units swapped,
values turned into strings, arrays, tables or huge integers, tables dropped.
Each mutant is checked (--check); some of those that pass also run briefly
(end_time shortened), and a run still going at the time limit is sent SIGTERM
and must stop (exit code 3) within 10 s.

Pass: no death by a signal, no raw C++ exception text, exit codes 0, 1 (with
a message of ours), 2 (bad input) or 3 (stopped on request), no hang (a check
past the time limit, or a run that does not stop on SIGTERM).

usage: fuzz_scenes.py BUILD_DIR SOURCE_DIR WORK_DIR [--seed 1] [--count 300] [--runs 20] [--limit 10]"""
import argparse
import collections
import copy
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
import tomllib

PROGRAMS = {("seepage",): "seepage_fe/seepage-fe", ("mpm",): "mpm_solid/mpm-solid",
            ("mpm", "seepage"): "coupler/outburst"}
# A brief run of each scene (scene.end_time), for the mutants that also run.
SHORT = {"drainage": '"1 d"', "elastic_block": '"0.002 s"', "granular_collapse": '"0.01 s"', "bar": '"0.001 s"',
         "gas_face": '"0.002 s"', "terzaghi": '"0.01 s"', "mandel": '"0.02 s"'}
RAW = ["terminate called", "what():", "std::", "basic_string", "stoul", "stod", "bad_alloc", "max_size()",
       "filesystem error", "Segmentation", "Aborted", "runtime error:", "AddressSanitizer", "LeakSanitizer"]
UNITS = ["m", "s", "ms", "MPa", "GPa", "deg", "rad", "kg/m3", "1/s", "m/s2", "m/s", "N", "kN/m", "Pa^-1",
         "m2/(MPa2 d)", "MPa^-0.5", "", "furlong", "m^1e400"]


# ---------------------------------------------------------------- TOML out

def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def is_table_array(v):
    return isinstance(v, list) and v and all(isinstance(x, dict) for x in v)


def toml_text(doc, path=()):
    out = []
    for k, v in doc.items():
        if not isinstance(v, dict) and not is_table_array(v):
            out.append(f"{json.dumps(k)} = {toml_value(v)}")
    for k, v in doc.items():
        sub = path + (json.dumps(k),)
        if isinstance(v, dict):
            out.append(f"\n[{'.'.join(sub)}]")
            out.append(toml_text(v, sub))
        elif is_table_array(v):
            for item in v:
                out.append(f"\n[[{'.'.join(sub)}]]")
                out.append(toml_text(item, sub))
    return "\n".join(x for x in out if x)


# ---------------------------------------------------------------- mutations

def places(doc, path=()):
    """Every (container, key) in the document, tables and array items included."""
    for k, v in list(doc.items()) if isinstance(doc, dict) else enumerate(doc):
        yield doc, k, path + (k,)
        if isinstance(v, (dict, list)):
            yield from places(v, path + (k,))


def scale_text(text, factor):
    m = re.match(r"^\s*([-+0-9.eE]+)\s*(.*)$", text)
    if not m:
        return text
    try:
        return f"{float(m.group(1)) * factor:g} {m.group(2)}".strip()
    except ValueError:
        return text


def mutate(doc, rng):
    """One mutation in place; returns what it did."""
    container, key, path = rng.choice(list(places(doc)))
    value = container[key]
    name = ".".join(str(p) for p in path)
    kind = rng.choice(["delete", "sign", "scale", "scale", "unit", "string", "array", "table", "integer",
                       "rename", "bool"])
    if kind == "delete" and isinstance(container, dict):
        del container[key]
    elif kind == "rename" and isinstance(container, dict):
        container[str(key) + rng.choice(["s", "_", "x"]) if rng.random() < 0.5 else str(key)[:-1]] = \
            container.pop(key)
    elif kind == "sign" and isinstance(value, (int, float)) and not isinstance(value, bool):
        container[key] = -value
    elif kind == "sign" and isinstance(value, str):
        container[key] = "-" + value
    elif kind == "scale":
        factor = 10.0 ** rng.choice([rng.randint(-30, 30), 300, -300])
        if isinstance(value, str):
            container[key] = scale_text(value, factor)
        elif isinstance(value, int) and not isinstance(value, bool):
            container[key] = int(min(max(value * factor, -2 ** 63), 2 ** 63 - 1))
        elif isinstance(value, float):
            container[key] = value * factor
        else:
            return mutate(doc, rng)
    elif kind == "unit" and isinstance(value, str):
        m = re.match(r"^\s*([-+0-9.eE]+)", value)
        container[key] = f"{m.group(1) if m else '1'} {rng.choice(UNITS)}".strip()
    elif kind == "string":
        container[key] = rng.choice(["", "abc", str(value)[:40], "1e400 s", "nan m"])
    elif kind == "array":
        container[key] = [value, value] if rng.random() < 0.5 else []
    elif kind == "table":
        container[key] = {"x": value} if rng.random() < 0.5 else {}
    elif kind == "integer":
        container[key] = rng.choice([0, -1, 2 ** 31, 2 ** 63 - 1, -2 ** 63, 4294967297])
    elif kind == "bool":
        container[key] = rng.random() < 0.5
    else:
        return mutate(doc, rng)
    return f"{kind} {name}"


# ---------------------------------------------------------------- running

def run(command, limit, stop_at_limit):
    """(exit code, output, outcome): outcome is "done", "stopped" (SIGTERM at
    the limit, then exit code 3) or "hang"."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               env=dict(os.environ, OMP_NUM_THREADS="1"))
    try:
        output, _ = process.communicate(timeout=limit)
        return process.returncode, output, "done"
    except subprocess.TimeoutExpired:
        if not stop_at_limit:
            process.kill()
            return None, process.communicate()[0], "hang"
        process.send_signal(signal.SIGTERM)
        try:
            output, _ = process.communicate(timeout=10)
            return process.returncode, output, "stopped" if process.returncode == 3 else "hang"
        except subprocess.TimeoutExpired:
            process.kill()
            return None, process.communicate()[0], "hang"


def judge(code, output, outcome, expect_stop):
    problems = []
    if outcome == "hang":
        problems.append("hang")
    elif code < 0:
        problems.append(f"killed by signal {-code}")
    elif code not in (0, 1, 2) and not (code == 3 and expect_stop):
        problems.append(f"exit code {code}")
    elif code == 1 and "[error]" not in output:
        problems.append("exit code 1 without an error message")
    problems += [f"raw '{r}'" for r in RAW if r in output]
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build")
    ap.add_argument("source")
    ap.add_argument("work")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=300, help="mutants checked")
    ap.add_argument("--runs", type=int, default=20, help="of those passing --check, how many also run")
    ap.add_argument("--limit", type=float, default=10, help="seconds a check or a run may take")
    args = ap.parse_args()
    rng = random.Random(args.seed)

    scenes = []
    for folder in sorted(os.listdir(os.path.join(args.source, "cases"))):
        for name in sorted(os.listdir(os.path.join(args.source, "cases", folder)) if os.path.isdir(
                os.path.join(args.source, "cases", folder)) else []):
            if name.endswith(".toml") and name not in ("study.toml", "schemes.toml"):
                scenes.append(os.path.join(args.source, "cases", folder, name))
    shutil.rmtree(args.work, ignore_errors=True)
    copies = {}
    for scene in scenes:
        folder = os.path.join(args.work, os.path.basename(os.path.dirname(scene)))
        if folder not in copies.values():
            shutil.copytree(os.path.dirname(scene), folder, ignore=shutil.ignore_patterns("study", "schemes", "*.py"))
        copies[scene] = folder

    counts = collections.Counter()
    failed_runs = collections.Counter()  # the messages of runs that failed (exit code 1)
    failures = []
    ran = 0
    start = time.monotonic()
    for i in range(args.count):
        scene = rng.choice(scenes)
        with open(scene, "rb") as f:
            doc = tomllib.load(f)
        original = copy.deepcopy(doc)
        did = [mutate(doc, rng) for _ in range(rng.choice([1, 1, 1, 2, 3]))]
        solvers = tuple(sorted(original["scene"]["solvers"]))
        program = os.path.join(args.build, PROGRAMS[solvers])
        mutant = os.path.join(copies[scene], f"mutant_{i:05d}.toml")
        with open(mutant, "w") as f:
            f.write(toml_text(doc) + "\n")
        code, output, outcome = run([program, mutant, "--check", "-q"], args.limit, False)
        counts[f"check exit {code if outcome == 'done' else outcome}"] += 1
        problems = judge(code, output, outcome, False)
        case = os.path.basename(os.path.dirname(scene))
        if not problems and code == 0 and ran < args.runs and case in SHORT:
            ran += 1
            out = os.path.join(args.work, "runs", f"mutant_{i:05d}")
            code, output, outcome = run([program, mutant, "-q", "-o", out, "--set", f"scene.end_time={SHORT[case]}",
                                         "--set", f"output.interval={SHORT[case]}"], args.limit, True)
            counts[f"run exit {code}" + (" (SIGTERM at the limit)" if outcome == "stopped" else "")
                   if outcome != "hang" else "run hang"] += 1
            problems = judge(code, output, outcome, True)
            if code == 1:
                error = next((line for line in reversed(output.splitlines()) if "[error]" in line), "")
                failed_runs[re.sub(r"[-+]?[0-9][0-9.e+-]*", "#", error.split("[error] ")[-1])[:160]] += 1
        if problems:
            last = [line for line in output.strip().splitlines() if line.strip()][-3:]
            failures.append(f"{mutant} ({case}: {'; '.join(did)}): {', '.join(problems)}\n    " + "\n    ".join(last))
        else:
            os.remove(mutant)
    wall = time.monotonic() - start
    signals = sum(1 for f in failures if "killed by signal" in f)
    hangs = sum(1 for f in failures if "hang" in f)
    print(f"fuzz: seed {args.seed}, {args.count} mutants of {len(scenes)} scenes checked, {ran} run, {wall:.0f} s")
    for outcome, n in sorted(counts.items()):
        print(f"  {outcome}: {n}")
    print(f"  signal deaths: {signals}; hangs: {hangs}; other failures: {len(failures) - signals - hangs}")
    if failed_runs:
        print("  runs that failed (exit code 1), by message (numbers as #):")
        for message, n in failed_runs.most_common():
            print(f"    {n} x {message}")
    for f in failures:
        print(f"FAIL {f}")
    if failures:
        sys.exit(1)


if __name__ == "__main__":
    main()
