"""Options of the Python tests: where the build is (for the programs) and a
short outburst run to report on; CTest passes both (tests/CMakeLists.txt)."""
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def pytest_addoption(parser):
    parser.addoption("--build", help="the build folder holding the programs (default: build/)")
    parser.addoption("--outburst-run", help="output folder of a short run of cases/outburst/outburst.toml")


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


@pytest.fixture
def outburst_run(request):
    path = request.config.getoption("--outburst-run")
    if path is None:
        pytest.skip("no outburst run to report on (pass --outburst-run)")
    if not os.path.isdir(path):
        pytest.fail(f"--outburst-run {path}: no such folder")
    return path
