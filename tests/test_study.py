#!/usr/bin/python3
"""cases/study.py on a stand-in method of known order (tests/study_fixture):
the measured order is 2, and an unknown knob is refused by name.

usage: test_study.py SOURCE_DIR WORK_DIR"""
import csv
import os
import subprocess
import sys


def main():
    source, work = sys.argv[1], sys.argv[2]
    fixture = os.path.join(source, "tests", "study_fixture")
    failures = []

    out = os.path.join(work, "known_order")
    done = subprocess.run([sys.executable, "-m", "cases.study", os.path.join(fixture, "study.toml"), "--out", out],
                          capture_output=True, text=True, cwd=source)
    if done.returncode != 0:
        sys.exit(f"the study failed: {done.stderr}")
    with open(os.path.join(out, "study_orders.csv")) as f:
        orders = {r["knob"]: r for r in csv.DictReader(f)}
    order = float(orders["h"]["order_in_value"])
    print(f"measured order {order:.4f} (R^2 {float(orders['h']['r2_value']):.6f}); expected 2")
    if abs(order - 2) > 1e-6:
        failures.append(f"order {order}, expected 2")
    with open(os.path.join(out, "study.csv")) as f:
        rows = list(csv.DictReader(f))
    # The error falls with h; a run is on the Pareto front unless another is
    # both faster and more accurate, and the most accurate always is.
    best = min(rows, key=lambda r: float(r["error"]))
    if best["pareto"] != "True" or best["h"] != "0.025":
        failures.append(f"the most accurate run ({best}) should be h = 0.025 and on the Pareto front")
    for name in ("study.md", "study.png"):
        if not os.path.getsize(os.path.join(out, name)):
            failures.append(f"{name} is empty")

    bad = os.path.join(work, "bad_knob.toml")
    with open(bad, "w") as f:
        f.write(f'scene = "{fixture}/scene.toml"\nprogram = "{fixture}/known_order.py"\n'
                f'measure = "{fixture}/measure.py"\n[[knobs]]\nname = "grid_sise"\nvalues = [1, 2]\n')
    done = subprocess.run([sys.executable, "-m", "cases.study", bad, "--out", os.path.join(work, "bad")],
                          capture_output=True, text=True, cwd=source)
    message = done.stderr.strip()
    print(f"unknown knob: exit {done.returncode}: {message}")
    if done.returncode == 0 or 'unknown knob "grid_sise"' not in message or "mpm_cell_size" not in message \
            or "bad_knob.toml" not in message:
        failures.append("an unknown knob must fail naming the file, the knob and the known ones")
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
