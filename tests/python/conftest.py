"""Options of the Python tests: where the build is (for the programs) and a
short outburst run to report on; CTest passes both (tests/CMakeLists.txt)."""
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def pytest_addoption(parser):
    parser.addoption("--build", default=os.path.join(REPO, "build"), help="the build folder holding the programs")
    parser.addoption("--outburst-run", help="output folder of a short run of cases/outburst/outburst.toml")


@pytest.fixture
def repo():
    return REPO


@pytest.fixture
def build(request):
    path = os.path.abspath(request.config.getoption("--build"))
    if not os.path.isdir(os.path.join(path, "coupler")):
        pytest.skip(f"no build at {path} (pass --build)")
    return path


@pytest.fixture
def outburst_run(request):
    path = request.config.getoption("--outburst-run")
    if path is None:
        pytest.skip("no outburst run to report on (pass --outburst-run)")
    return path
