"""Options of the Python tests: where the build is (for the programs), a
short outburst run to report on and a coarse run of the 3D granular collapse
to measure; CTest passes them (tests/CMakeLists.txt)."""
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def pytest_addoption(parser):
    parser.addoption("--build", help="the build folder holding the programs (default: build/)")
    parser.addoption("--outburst-run", help="output folder of a short run of cases/outburst/outburst.toml")
    parser.addoption("--collapse-3d-run",
                     help="output folder of a run of cases/granular_collapse_3d/granular_collapse_3d.toml")


@pytest.fixture
def repo():
    return REPO


# A folder named on the command line (as CTest names them) must be there: a
# skip would pass under CTest. Without the option, a test that needs it skips.
@pytest.fixture
def build(request):
    given = request.config.getoption("--build")
    path = os.path.abspath(given or os.path.join(REPO, "build"))
    if not os.path.isdir(os.path.join(path, "coupler")):
        if given:
            pytest.fail(f"--build {given}: no build there")
        pytest.skip(f"no build at {path} (pass --build)")
    return path


def given_run(request, option, what):
    path = request.config.getoption(option)
    if path is None:
        pytest.skip(f"no {what} (pass {option})")
    if not os.path.isdir(path):
        pytest.fail(f"{option} {path}: no such folder")
    return path


@pytest.fixture
def outburst_run(request):
    return given_run(request, "--outburst-run", "outburst run to report on")


@pytest.fixture
def collapse_3d_run(request):
    return given_run(request, "--collapse-3d-run", "3D granular collapse run to measure")
