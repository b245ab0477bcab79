"""cases.study on a stand-in method of known order (tests/study_fixture): the
measured order is 2, and an unknown knob is refused by name."""
import csv
import os
import subprocess
import sys

import pytest

from cases import study


def run_study(repo, *args):
    return subprocess.run([sys.executable, "-m", "cases.study", *args], capture_output=True, text=True, cwd=repo)


def test_measures_a_known_order(repo, tmp_path):
    out = tmp_path / "known_order"
    done = run_study(repo, os.path.join(repo, "tests", "study_fixture", "study.toml"), "--out", str(out))
    assert done.returncode == 0, done.stderr
    with open(out / "study_orders.csv") as f:
        orders = {r["knob"]: r for r in csv.DictReader(f)}
    assert float(orders["h"]["order_in_value"]) == pytest.approx(2, abs=1e-6)
    with open(out / "study.csv") as f:
        rows = list(csv.DictReader(f))
    # The error falls with h; a run is on the Pareto front unless another is
    # both faster and more accurate, and the most accurate always is.
    best = min(rows, key=lambda r: float(r["error"]))
    assert (best["h"], best["pareto"]) == ("0.025", "True")
    for name in ("study.md", "study.png"):
        assert os.path.getsize(out / name) > 0


def test_refuses_an_unknown_knob_by_name(repo, tmp_path):
    fixture = os.path.join(repo, "tests", "study_fixture")
    bad = tmp_path / "bad_knob.toml"
    bad.write_text(f'scene = "{fixture}/scene.toml"\nprogram = "{fixture}/known_order.py"\n'
                   f'measure = "{fixture}/measure.py"\n[[knobs]]\nname = "grid_sise"\nvalues = [1, 2]\n')
    done = run_study(repo, str(bad), "--out", str(tmp_path / "bad"))
    assert done.returncode != 0
    for part in ('unknown knob "grid_sise"', "mpm_cell_size", "bad_knob.toml"):
        assert part in done.stderr


def test_measures_load_inside_the_package_and_out(repo):
    inside = study.load_measure(os.path.join(repo, "cases", "mandel", "..", "final_pressure.py"))
    assert inside.__name__ == "cases.final_pressure"
    outside = study.load_measure(os.path.join(repo, "tests", "study_fixture", "measure.py"))
    assert hasattr(outside, "errors")


def test_knob_values():
    assert study.numeric("24 h") == 86400.0
    assert study.numeric([38, 2]) == 76.0
    assert study.numeric("bspline") is None
    assert study.short("0.3333333333333333 m") == "0.333 m"
    assert study.short("iqn_ils") == "iqn_ils"
