#!/usr/bin/python3
"""Fuzzing the programs with mutated shipped scenes: keys deleted or renamed,
signs flipped, values scaled by 1e-30..1e30 (and 1e+-300), units swapped,
values turned into strings, arrays, tables or huge integers, tables dropped.
Each mutant is checked (--check); some of those that pass also run briefly
(end_time shortened), and a run still going at the time limit is sent SIGTERM
and must stop (exit code 3) within 10 s.

Then three shapes of their own (issue 57): deep nesting (a unit's
parentheses, a dotted key, a [header], arrays, inline tables or a --set key,
31 to 300,000 levels deep), corrupted meshes (a Gmsh file with a digit, a
token or a line changed, a line gone or doubled, the file cut short; checked
with --check), and corrupted checkpoints (bits flipped anywhere in a
checkpoint taken mid-run by SIGTERM; continued with --restart, which must
refuse it, exit code 2, or end with the results of the run never stopped, bit
for bit).

Pass: no death by a signal, no raw C++ exception text, exit codes 0, 1 (with
a message of ours), 2 (bad input) or 3 (stopped on request), no hang (a check
past the time limit, or a run that does not stop on SIGTERM); a damaged
checkpoint refused or continued exactly.

usage: fuzz_scenes.py BUILD_DIR SOURCE_DIR WORK_DIR [--seed 1] [--count 300] [--runs 20] [--limit 10]
                      [--nesting 30] [--meshes 40] [--checkpoints 16]"""
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


# ---------------------------------------------------------------- deep nesting

def nested(text, rng):
    """The scene text, and the --set overrides, with one structure nested
    deep; and what it did."""
    depth = rng.choice([31, 32, 33, 100, 5000, 50000, 300000])
    kind = rng.choice(["unit", "key", "header", "arrays", "tables", "set key"])
    key = ".".join(["a"] * depth)
    if kind == "unit":
        quantities = list(re.finditer(r'"([-+0-9.eE]+) ([A-Za-z][^"]*)"', text))
        if quantities:
            m = rng.choice(quantities)
            return (text[:m.start()] + f'"{m.group(1)} {"(" * depth}{m.group(2)}{")" * depth}"' + text[m.end():], [],
                    f"a unit in {depth} parentheses")
        kind = "key"
    if kind == "set key":
        depth = min(depth, 50000)  # an argument may hold 128 kB
        return text, [".".join(["a"] * depth) + "=1"], f"a --set key of {depth} parts"
    added = {"key": f"{key} = 1\n", "header": f"[{key}]\nb = 1\n", "arrays": "x = " + "[" * depth + "]" * depth + "\n",
             "tables": "x = " + "{a = " * depth + "1" + " }" * depth + "\n"}[kind]
    # Before the first table, where a key or array is the top level's.
    first = text.find("\n[")
    at = first + 1 if first >= 0 else len(text)
    if kind == "header":
        at = len(text)
    return text[:at] + added + text[at:], [], f"{kind} {depth} deep"


# ---------------------------------------------------------------- corrupted meshes

def corrupted(lines, rng):
    """A Gmsh file's lines with one change; and what it was."""
    lines = list(lines)
    k = rng.randrange(len(lines))
    kind = rng.choice(["digit", "token", "delete", "double", "swap", "cut"])
    if kind == "digit" and any(c.isdigit() for c in lines[k]):
        at = rng.choice([i for i, c in enumerate(lines[k]) if c.isdigit()])
        lines[k] = lines[k][:at] + rng.choice("0123456789") + lines[k][at + 1:]
    elif kind == "token" and lines[k].split():
        tokens = lines[k].split()
        tokens[rng.randrange(len(tokens))] = rng.choice(["-1", "0", "2147483648", "9223372036854775808", "1e308",
                                                         "nan", "inf", "x", "1.5", "$Nodes", '"a"'])
        lines[k] = " ".join(tokens)
    elif kind == "delete":
        del lines[k]
    elif kind == "double":
        lines.insert(k, lines[k])
    elif kind == "swap" and len(lines[k].split()) > 1:
        tokens = lines[k].split()
        i, j = rng.sample(range(len(tokens)), 2)
        tokens[i], tokens[j] = tokens[j], tokens[i]
        lines[k] = " ".join(tokens)
    else:
        lines = lines[:k]
        kind = "cut"
    return lines, f"{kind} at line {k + 1}"


# ---------------------------------------------------------------- running

def run(command, limit, stop_at_limit):
    """(exit code, output, outcome): outcome is "done", "stopped" (SIGTERM at
    the limit, then exit code 3) or "hang"."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
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


# ---------------------------------------------------------------- corrupted checkpoints

# (program, scene, overrides) of runs stopped by SIGTERM after their first
# checkpoint, whose checkpoint is then damaged and continued.
CHECKPOINTED = [
    ("mpm_solid/mpm-solid", "granular_collapse/granular_collapse.toml",
     ['scene.end_time="0.2 s"', 'output.interval="0.05 s"', 'output.checkpoint_interval="0.01 s"']),
    ("seepage_fe/seepage-fe", "drainage/drainage.toml",
     ['seepage.max_time_step="30 min"', 'output.checkpoint_interval="1 d"']),
    ("coupler/outburst", "gas_face/gas_face.toml",
     ['output.checkpoint_interval="1 ms"']),
]


def checkpointed(build, source, work, case, limit):
    """(command, the run never stopped, a pristine copy of a run stopped
    mid-way by SIGTERM), or a reason it could not be made."""
    program, scene, overrides = case
    name = os.path.basename(os.path.dirname(scene))

    def line(out):
        command = [os.path.join(build, program), os.path.join(source, "cases", scene), "-q", "-o", out, "-j", "1"]
        for o in overrides:
            command += ["--set", o]
        return command
    whole, stopped = os.path.join(work, f"{name}_whole"), os.path.join(work, f"{name}_stopped")
    code, output, _ = run(line(whole), 4 * limit, False)
    if code != 0:
        return f"{name}: the run to compare with ended with exit code {code}: {output.strip()[-200:]}"
    for _ in range(4):
        shutil.rmtree(stopped, ignore_errors=True)
        process = subprocess.Popen(line(stopped), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                   env=dict(os.environ, OMP_NUM_THREADS="1"))
        while process.poll() is None and not os.path.exists(os.path.join(stopped, "checkpoint.h5")):
            time.sleep(0.002)
        process.send_signal(signal.SIGTERM)
        if process.wait(timeout=60) == 3:
            return line, whole, stopped
    return f"{name}: the run ended before SIGTERM four times"


def flip_bits(path, rng):
    """Flips 1 to 3 bits at random bytes of the file; returns where."""
    with open(path, "r+b") as f:
        size = os.path.getsize(path)
        where = sorted(rng.randrange(size) for _ in range(rng.choice([1, 1, 2, 3])))
        for at in where:
            f.seek(at)
            byte = f.read(1)[0]
            f.seek(at)
            f.write(bytes([byte ^ (1 << rng.randrange(8))]))
    return where


def same_results(reference, other):
    """Differences between two run folders: the snapshots each index lists
    and the last checkpoint (run_folder.py)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from run_folder import compare_checkpoints, compare_listed  # noqa: E402
    found = []
    for index in ("seepage.xdmf", "particles.xdmf"):
        if os.path.exists(os.path.join(reference, index)):
            found += compare_listed(reference, other, index)
    return found + compare_checkpoints(reference, other)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build")
    ap.add_argument("source")
    ap.add_argument("work")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=300, help="mutants checked")
    ap.add_argument("--runs", type=int, default=20, help="of those passing --check, how many also run")
    ap.add_argument("--limit", type=float, default=10, help="seconds a check or a run may take")
    ap.add_argument("--nesting", type=int, default=30, help="scenes nested deep, checked")
    ap.add_argument("--meshes", type=int, default=40, help="corrupted meshes, checked")
    ap.add_argument("--checkpoints", type=int, default=16, help="corrupted checkpoints, continued")
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

    # Deep nesting, in any scene.
    for i in range(args.nesting):
        scene = rng.choice(scenes)
        with open(scene) as f:
            text, overrides, did = nested(f.read(), rng)
        mutant = os.path.join(copies[scene], f"nested_{i:05d}.toml")
        with open(mutant, "w") as f:
            f.write(text)
        with open(scene, "rb") as f:
            solvers = tuple(sorted(tomllib.load(f)["scene"]["solvers"]))
        command = [os.path.join(args.build, PROGRAMS[solvers]), mutant, "--check", "-q"]
        for o in overrides:
            command += ["--set", o]
        code, output, outcome = run(command, args.limit, False)
        counts[f"nesting exit {code if outcome == 'done' else outcome}"] += 1
        problems = judge(code, output, outcome, False)
        if problems:
            failures.append(f"{mutant} ({did}): {', '.join(problems)}")
        else:
            os.remove(mutant)

    # Corrupted meshes, of the scenes that read one.
    meshed = [s for s in scenes if re.search(r'^file = "([^"]+\.msh)"', open(s).read(), re.M)]
    for i in range(args.meshes if meshed else 0):
        scene = rng.choice(meshed)
        with open(scene) as f:
            text = f.read()
        mesh = re.search(r'^file = "([^"]+\.msh)"', text, re.M).group(1)
        with open(os.path.join(copies[scene], mesh)) as f:
            lines, did = corrupted(f.read().split("\n"), rng)
        name = f"mesh_{i:05d}"
        with open(os.path.join(copies[scene], name + ".msh"), "w") as f:
            f.write("\n".join(lines))
        mutant = os.path.join(copies[scene], name + ".toml")
        with open(mutant, "w") as f:
            f.write(text.replace(f'file = "{mesh}"', f'file = "{name}.msh"'))
        with open(scene, "rb") as f:
            solvers = tuple(sorted(tomllib.load(f)["scene"]["solvers"]))
        code, output, outcome = run([os.path.join(args.build, PROGRAMS[solvers]), mutant, "--check", "-q"],
                                    args.limit, False)
        counts[f"mesh exit {code if outcome == 'done' else outcome}"] += 1
        problems = judge(code, output, outcome, False)
        if problems:
            failures.append(f"{mutant} ({os.path.basename(mesh)}: {did}): {', '.join(problems)}")
        else:
            os.remove(mutant)
            os.remove(os.path.join(copies[scene], name + ".msh"))

    # Corrupted checkpoints: refused, or continued to the results of the run
    # never stopped.
    made = []
    for case in CHECKPOINTED if args.checkpoints else []:
        got = checkpointed(args.build, args.source, os.path.join(args.work, "checkpoints"), case, args.limit)
        if isinstance(got, str):
            failures.append(got)
        else:
            made.append(got)
    for i in range(args.checkpoints if made else 0):
        line, whole, stopped = rng.choice(made)
        out = f"{stopped}_{i:05d}"
        shutil.copytree(stopped, out)
        where = flip_bits(os.path.join(out, "checkpoint.h5"), rng)
        code, output, outcome = run(line(out) + ["--restart"], 4 * args.limit, False)
        counts[f"checkpoint exit {code if outcome == 'done' else outcome}"] += 1
        problems = judge(code, output, outcome, False)
        if not problems and code == 1:
            problems.append("exit code 1: a damaged checkpoint must be refused (exit code 2) or continue exactly")
        if not problems and code == 0:
            problems += [f"restarted to other results: {d}" for d in same_results(whole, out)[:3]]
        if problems:
            last = [x for x in output.strip().splitlines() if x.strip()][-2:]
            failures.append(f"{out} (bits flipped at bytes {where}): {', '.join(problems)}\n    " + "\n    ".join(last))
        else:
            shutil.rmtree(out)

    wall = time.monotonic() - start
    signals = sum(1 for f in failures if "killed by signal" in f)
    hangs = sum(1 for f in failures if "hang" in f)
    print(f"fuzz: seed {args.seed}, {args.count} mutants of {len(scenes)} scenes checked, {ran} run, "
          f"{args.nesting} nested deep, {args.meshes} meshes corrupted, {args.checkpoints} checkpoints damaged, "
          f"{wall:.0f} s")
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
