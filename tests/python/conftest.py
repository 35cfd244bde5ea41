"""pytest setup for the erodem Python tests.

The tests run against a build tree: ``ERODEM_BUILD_DIR`` (default ``build``, relative to the
repository root) must hold ``python/erodem`` (the package with its compiled module, built by
the CMake target ``_erodem``) and ``cli/erodem`` (for the CLI comparisons). Without a build
tree there, an installed ``erodem`` (``pip install .``) is used and the CLI tests are skipped.

Run: ``ERODEM_BUILD_DIR=build python3 -m pytest tests/python`` (scripts/test.sh does).
"""

import os
import subprocess
import sys
import tempfile

import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.path.join(REPO, os.environ.get("ERODEM_BUILD_DIR", "build"))
PACKAGE_DIR = os.path.join(BUILD, "python")
if os.path.isdir(os.path.join(PACKAGE_DIR, "erodem")):
    sys.path.insert(0, PACKAGE_DIR)
    # worker processes (spawn, dask) find the same package
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [PACKAGE_DIR] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    )
os.environ.setdefault(
    "POCL_CACHE_DIR",
    os.path.join(BUILD if os.path.isdir(BUILD) else tempfile.gettempdir(), "pocl-cache"),
)
os.makedirs(os.environ["POCL_CACHE_DIR"], exist_ok=True)

DEM_DIR = os.path.abspath(os.path.join(REPO, "..", "shared", "data", "dem"))
TUJUNGA = os.path.join(DEM_DIR, "big_tujunga", "srtm_bigtujunga30m_utm11.tif")
VOLCANO = os.path.join(DEM_DIR, "volcano", "volcano_northup_10m.tif")


@pytest.fixture(scope="session")
def erodem():
    import erodem as module

    print("erodem from", module.__file__)
    return module


@pytest.fixture(scope="session")
def cli():
    """The erodem executable of the build tree."""
    path = os.path.join(BUILD, "cli", "erodem")
    if not os.path.exists(path):
        pytest.skip("no CLI at %s (set ERODEM_BUILD_DIR)" % path)
    return path


@pytest.fixture(scope="session")
def tujunga():
    if not os.path.exists(TUJUNGA):
        pytest.skip("missing %s" % TUJUNGA)
    return TUJUNGA


@pytest.fixture(scope="session")
def volcano():
    if not os.path.exists(VOLCANO):
        pytest.skip("missing %s" % VOLCANO)
    return VOLCANO


@pytest.fixture(scope="session")
def opencl_available(erodem, volcano):
    """Whether the OpenCL backend runs here (PoCL counts)."""
    try:
        erodem.Simulation(erodem.read_dem(volcano, cell_size=10.0), backend="opencl", time__steps=1)
        return True
    except ValueError as e:
        print("OpenCL not available:", e)
        return False


def run_cli(cli, *args, check=True):
    """Runs the CLI; returns the CompletedProcess."""
    r = subprocess.run([cli, *args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError("%s exited %d:\n%s%s" % (args, r.returncode, r.stdout, r.stderr))
    return r
