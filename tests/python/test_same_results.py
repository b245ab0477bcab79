"""scripts/same-results.py, which the bit-for-bit check of a refactor
(scripts/compare-builds.sh) rests on: two runs of a scene are equal, a run one
ulp off is not, nor one of another length, and a folder that is not a run is
refused."""
import os
import subprocess

import h5py
import numpy as np


def run(build, repo, out, *overrides):
    line = [os.path.join(build, "mpm_solid", "mpm-solid"), os.path.join(repo, "cases", "bar", "bar.toml"),
            "-q", "-j", "1", "-o", str(out)]
    for o in overrides:
        line += ["--set", o]
    subprocess.run(line, check=True)


def same(repo, a, b):
    return subprocess.run(["/usr/bin/python3", os.path.join(repo, "scripts", "same-results.py"), str(a), str(b)],
                          capture_output=True, text=True)


def test_equal_runs_differ_by_one_ulp_and_refuse_other_folders(build, repo, tmp_path):
    run(build, repo, tmp_path / "a")
    run(build, repo, tmp_path / "b")
    r = same(repo, tmp_path / "a", tmp_path / "b")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "bit for bit" in r.stdout

    # One velocity of the last snapshot one ulp off.
    last = sorted(n for n in os.listdir(tmp_path / "b") if n.startswith("particles_") and n.endswith(".h5"))[-1]
    with h5py.File(tmp_path / "b" / last, "a") as f:
        v = f["particles/velocity"]
        first = v[0]
        first[0] = np.nextafter(first[0], np.inf)
        v[0] = first
    r = same(repo, tmp_path / "a", tmp_path / "b")
    assert r.returncode == 1
    assert f"{last}:particles/velocity differs" in r.stdout

    run(build, repo, tmp_path / "c", 'scene.end_time="0.01 s"')
    r = same(repo, tmp_path / "a", tmp_path / "c")
    assert r.returncode == 1
    assert "mpm_history.csv" in r.stdout

    (tmp_path / "empty").mkdir()
    r = same(repo, tmp_path / "a", tmp_path / "empty")
    assert r.returncode == 2
    assert "expected a run folder" in r.stderr
