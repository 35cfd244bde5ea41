"""The OpenCL objects are released before the interpreter exits (issue 19).

The OpenCL backend keeps each device's context and built program for later simulations. They
used to be released by a static destructor, after the OpenCL implementation may have begun its
own teardown: under Oclgrind every process then aborted at exit ("corrupted double-linked
list", exit 134) after finishing its work. The module now releases them from ``atexit``
(``_erodem.release_opencl_runtimes``). Each test runs a fresh interpreter that makes and drops
OpenCL simulations, keeps one alive to the end, and must exit 0; once on the default device
(PoCL here) and once under Oclgrind where it is installed (which shows the old abort).
"""

import os
import shutil
import subprocess
import sys

import pytest

SCRIPT = r"""
import erodem
from erodem import _erodem

def simulation():
    sim = erodem.Simulation(backend="opencl", dem__synthetic="hill", dem__size=16,
                            time__steps=2, rain__rate="50 mm/h")
    sim.step(2)
    return sim

dropped = simulation()
depth = float(dropped.water_depth.sum())
del dropped
# no simulation holds the runtime any more: released now
assert _erodem.release_opencl_runtimes() == 0
kept = simulation()  # builds the runtime again
assert float(kept.water_depth.sum()) == depth
assert _erodem.release_opencl_runtimes() == 1  # held by `kept` until it goes
again = simulation()  # a runtime of its own, released at exit by atexit
print("lifetimes ok", kept.device)
"""


def run_script(prefix, env_extra):
    env = dict(os.environ)
    env.update(env_extra)
    return subprocess.run(
        prefix + [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env
    )


def check(r):
    assert r.returncode == 0, "exit %d:\n%s%s" % (r.returncode, r.stdout, r.stderr[-3000:])
    assert "lifetimes ok" in r.stdout


def test_opencl_simulations_are_released_and_the_interpreter_exits_0(erodem, opencl_available):
    if not opencl_available:
        pytest.skip("no OpenCL device")
    check(run_script([], {}))


def test_under_oclgrind_the_interpreter_exits_0(erodem, opencl_available):
    oclgrind = shutil.which("oclgrind")
    if oclgrind is None:
        pytest.skip("oclgrind not installed")
    if not opencl_available:
        pytest.skip("no OpenCL backend")
    r = run_script([oclgrind], {"ERODEM_OPENCL_DEVICE": "Oclgrind:"})
    check(r)
    assert "Oclgrind" in r.stdout
