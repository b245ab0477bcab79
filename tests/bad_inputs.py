#!/usr/bin/python3
"""Runs the bad-input catalogue (tests/bad_inputs.toml): each case's exit code
and the words its message must hold, and for every case that no program died
by a signal or printed a raw C++ exception text.

usage: bad_inputs.py CATALOGUE BUILD_DIR SOURCE_DIR WORK_DIR [NAME_PART]"""
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import tomllib

PROGRAMS = {"seepage-fe": "seepage_fe/seepage-fe", "mpm-solid": "mpm_solid/mpm-solid", "outburst": "coupler/outburst"}
# What escapes when an exception is not turned into a message of ours.
RAW = ["terminate called", "what():", "std::", "basic_string", "stoul", "stod", "bad_alloc", "max_size()",
       "filesystem error", "Segmentation", "Aborted", "runtime error:", "AddressSanitizer", "LeakSanitizer"]


def replaced(text, edits, what):
    for old, new in edits:
        if old not in text:
            raise ValueError(f"the catalogue's edit of {what} finds no {old!r}")
        text = text.replace(old, new, 1)
    return text


def prepare(case, source, work):
    """The scene path of the case: the shipped one, or an edited copy of its folder."""
    scene = case["scene"] if os.path.isabs(case["scene"]) else os.path.join(source, "cases", case["scene"])
    if not case.get("replace") and not case.get("mesh_replace"):
        return scene
    folder = os.path.join(work, "scene")
    shutil.copytree(os.path.dirname(scene), folder, ignore=shutil.ignore_patterns("study", "schemes"))
    copy = os.path.join(folder, os.path.basename(scene))
    edits = [(copy, case.get("replace", [])), (os.path.join(folder, case.get("mesh", "")), case.get("mesh_replace", []))]
    for path, pairs in edits:
        if pairs:
            with open(path) as f:
                text = replaced(f.read(), pairs, os.path.basename(path))
            with open(path, "w") as f:
                f.write(text)
    return copy


def run_case(case, build, source, root):
    work = os.path.join(root, re.sub(r"[^a-z0-9]+", "_", case["name"].lower()))
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene = prepare(case, source, work)
    extra = [a.replace("SCENE", scene).replace("DIR", os.path.join(work, "out")) for a in case.get("args", [])]
    command = [os.path.join(build, PROGRAMS[case["program"]]), scene, "-q"] + extra
    if not case.get("run"):
        command.append("--check")
    for s in case.get("set", []):
        command += ["--set", s]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=120,
                              env=dict(os.environ, OMP_NUM_THREADS="1"))
    except subprocess.TimeoutExpired:
        return case, None, "", ["no end within 120 s"]
    output = done.stderr + done.stdout
    problems = []
    if done.returncode != case["exit"]:
        problems.append(f"exit code {done.returncode}, expected {case['exit']}")
    problems += [f"no '{w}'" for w in case["words"] if w not in output]
    problems += [f"raw '{r}'" for r in RAW if r in output]
    return case, done.returncode, output, problems


def main():
    catalogue, build, source, work = sys.argv[1:5]
    only = sys.argv[5] if len(sys.argv) > 5 else ""
    with open(catalogue, "rb") as f:
        cases = [c for c in tomllib.load(f)["case"] if only in c["name"]]
    names = [c["name"] for c in cases]
    if len(set(names)) != len(names):
        sys.exit("the catalogue names a case twice")
    # A case that runs writes its output: into its own folder, not the
    # source tree's results/, where a second run of the suite finds it.
    unplaced = [c["name"] for c in cases if c.get("run") and "-o" not in c.get("args", [])]
    if unplaced:
        sys.exit(f"cases that run without -o (give args = [\"-o\", \"DIR\"]): {', '.join(unplaced)}")
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        for case, code, output, problems in pool.map(lambda c: run_case(c, build, source, work), cases):
            lines = [line for line in output.strip().splitlines() if line.strip()]
            message = next((line for line in reversed(lines) if "--help" not in line), "")
            print(f"{'FAIL' if problems else 'ok  '} {case['program']:10} exit {code}  {case['name']}: "
                  f"{message[:300]}")
            if problems:
                failed += 1
                print(f"     {'; '.join(problems)}")
    programs = sorted({c["program"] for c in cases})
    print(f"{len(cases)} cases ({', '.join(f'{p} {names_of(cases, p)}' for p in programs)}), {failed} failed")
    if failed:
        sys.exit(1)


def names_of(cases, program):
    return sum(c["program"] == program for c in cases)


if __name__ == "__main__":
    main()
