#!/usr/bin/python3
"""cases/effect_cost.py on two shipped scenes, briefly: it removes exactly the
effects each scene names, every edited scene runs, and the rest are listed as
not named.

usage: test_effect_cost.py SOURCE_DIR BUILD_DIR WORK_DIR"""
import csv
import os
import subprocess
import sys

CASES = [
    ("granular_collapse/granular_collapse.toml", '"0.01 s"',
     ["every effect on", "without plasticity", "without friction", "without gravity"]),
    ("outburst/outburst.toml", '"0.004 s"',
     ["every effect on", "without seepage", "without damage", "without friction", "without gravity",
      "without permeability coupling"]),
]


def main():
    source, build, work = sys.argv[1:4]
    failures = []
    for scene, end, expected in CASES:
        out = os.path.join(work, scene.split("/")[0])
        done = subprocess.run([sys.executable, "-m", "cases.effect_cost",
                               os.path.join(source, "cases", scene), "--set", f"scene.end_time={end}",
                               "--repeats", "1", "--build", build, "--out", out], capture_output=True, text=True,
                              cwd=source)
        if done.returncode != 0:
            failures.append(f"{scene}: {done.stderr.strip()}")
            continue
        with open(os.path.join(out, "effect_cost.csv")) as f:
            rows = list(csv.DictReader(f))
        variants = [r["variant"] for r in rows]
        broken = [f"{r['variant']}: {r['note']}" for r in rows if r["note"]]
        print(f"{scene}: {variants}; failed runs: {broken or 'none'}")
        if variants != expected:
            failures.append(f"{scene}: variants {variants}, expected {expected}")
        if broken:
            failures.append(f"{scene}: {broken}")
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
