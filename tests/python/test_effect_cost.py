"""cases.effect_cost on two shipped scenes, briefly: it removes exactly the
effects each scene names, every edited scene runs, and the rest are listed as
not named."""
import csv
import os
import subprocess
import sys

import pytest


@pytest.mark.parametrize("scene, end, expected", [
    ("granular_collapse/granular_collapse.toml", '"0.01 s"',
     ["every effect on", "without plasticity", "without friction", "without gravity"]),
    ("outburst/outburst.toml", '"0.004 s"',
     ["every effect on", "without seepage", "without damage", "without friction", "without gravity",
      "without permeability coupling"]),
])
def test_removes_each_named_effect(repo, build, tmp_path, scene, end, expected):
    done = subprocess.run([sys.executable, "-m", "cases.effect_cost", os.path.join(repo, "cases", scene),
                           "--set", f"scene.end_time={end}", "--repeats", "1", "--build", build,
                           "--out", str(tmp_path)], capture_output=True, text=True, cwd=repo)
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "effect_cost.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["variant"] for r in rows] == expected
    assert [f"{r['variant']}: {r['note']}" for r in rows if r["note"]] == []
