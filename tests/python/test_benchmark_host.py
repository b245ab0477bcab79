"""The benchmark programs name the processor in their CSVs with the words the
comparison scripts use (common/host.hpp, scripts/builds.py's host()), so that
cases.readme_tables writes the same line above a table from either."""
import csv
import os
import subprocess
import sys

from cases import readme_tables

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "scripts"))
import builds  # noqa: E402


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_mpm_benchmark_names_the_host(build, tmp_path):
    out = tmp_path / "mpm.csv"
    subprocess.run([os.path.join(build, "mpm_solid", "mpm-benchmark"), "--csv", str(out), "--shape", "linear",
                    "--material", "elastic", "--", "100"], check=True, capture_output=True)
    rows = rows_of(out)
    assert [r["host"] for r in rows] == [builds.host()]
    assert readme_tables.on_host(rows) == [f"On {builds.host()}:", ""]


def test_seepage_benchmark_names_the_host(build, tmp_path):
    newton, orderings = tmp_path / "newton.csv", tmp_path / "orderings.csv"
    subprocess.run([os.path.join(build, "seepage_fe", "seepage-benchmark"), "--csv", str(newton), "--orderings-csv",
                    str(orderings), "--rounds", "1", "4"], check=True, capture_output=True)
    for path in (newton, orderings):
        rows = rows_of(path)
        assert rows and {r["host"] for r in rows} == {builds.host()}


def test_rows_naming_no_host_get_no_line():
    assert readme_tables.on_host([{"a": "1"}, {"a": "2", "host": ""}]) == []
