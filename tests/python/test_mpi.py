"""Python under mpirun: each process runs its own whole simulation (docs/mpi.md, python.md).

An ensemble script starts its members with ``mpirun -np N python3 script.py`` and lets mpi4py
tell each process which member it is. Only ``erodem run`` decomposes a grid into bands of rows
(``parallel::decompose``, called by its ``run()`` alone); a Python process in which mpi4py
initialised MPI is one member that runs its whole grid.

Before 2026-11-29, such a process split its simulations into bands like a rank of
``erodem run``: the two members below, with different rain, ran as one grid, each half with its
own rain, and both got the same mixture (2760 and 2663 of the 4608 values of their depth and
bed differed from each member's own run). The bound is 0 values: one process and one member
of the ensemble run the same code on the same numbers.
"""

import json
import os
import shutil
import subprocess
import sys
import importlib.util

import numpy as np
import pytest

# One member of the ensemble: 48 x 48 cells of a cone with ripples, 50 mm/h of rain more per
# member, erosion on, adaptive steps.
MEMBER = r"""
def member(erodem, np, k):
    z = 60 - np.hypot(*np.mgrid[-24:24, -24:24]) * 2.5 + np.sin(np.arange(48))[None, :]
    dem = erodem.DEM.from_array(z, cell_size=10.0)
    return erodem.Simulation(dem, "cpu", rain__rate="%d mm/h" % (50 + 50 * k),
                             time__adaptive=True, time__dt_max=0.5, erosion__enabled=True,
                             initial__water_depth=0.05)
"""

SCRIPT = (
    r"""
import json, os, sys
from mpi4py import MPI  # MPI first, as an ensemble script does
import numpy as np
import erodem
"""
    + MEMBER
    + r"""
out = sys.argv[1]
comm = MPI.COMM_WORLD
k = comm.Get_rank()
sim = member(erodem, np, k)
sim.run(steps=30, output=os.path.join(out, "member%d.h5" % k))
np.save(os.path.join(out, "member%d.npy" % k),
        np.stack([np.array(sim.water_depth), np.array(sim.bed)]))
with open(os.path.join(out, "member%d.json" % k), "w") as f:
    json.dump({"rank": k, "size": comm.Get_size(), "device": sim.device, "time": sim.time}, f)
comm.Barrier()
"""
)


def test_an_ensemble_under_mpirun_runs_each_member_whole(erodem, tmp_path):
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("no mpirun (scripts/setup.sh installs OpenMPI)")
    if importlib.util.find_spec("mpi4py") is None:
        pytest.skip("no mpi4py (scripts/setup.sh installs it: pip install mpi4py)")
    script = tmp_path / "ensemble.py"
    script.write_text(SCRIPT)
    env = dict(os.environ)
    env.pop("OMP_NUM_THREADS", None)  # the members share the cores by themselves
    r = subprocess.run(
        [mpirun, "--allow-run-as-root", "--oversubscribe", "--bind-to", "none", "-np", "2",
         sys.executable, str(script), str(tmp_path)],
        capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, "mpirun exited %d:\n%s%s" % (r.returncode, r.stdout, r.stderr)

    namespace = {}
    exec(MEMBER, namespace)
    cores = len(os.sched_getaffinity(0))
    for k in (0, 1):
        with open(tmp_path / ("member%d.json" % k)) as f:
            info = json.load(f)
        print("member %d of %d: %s, t = %g s" % (k, info["size"], info["device"], info["time"]))
        # both processes were one launch of two (mpi4py saw them together) ...
        assert info["size"] == 2
        # ... yet each ran its whole grid, on its share of the machine's cores
        assert "MPI ranks" not in info["device"]
        threads = int(info["device"].split(" thread")[0].rsplit(" ", 1)[1])
        assert threads == max(1, cores // 2), (threads, cores)

        alone = namespace["member"](erodem, np, k)
        alone.step(30)
        expected = np.stack([np.array(alone.water_depth), np.array(alone.bed)])
        got = np.load(tmp_path / ("member%d.npy" % k))
        differ = int(np.sum(~((got == expected) | (np.isnan(got) & np.isnan(expected)))))
        print("member %d: %d of %d values of the depth and bed differ from its run in one "
              "process (bound 0)" % (k, differ, expected.size))
        assert differ == 0
        assert info["time"] == alone.time

        # its own result file, whole, as one process writes it
        ds = erodem.open_run(str(tmp_path / ("member%d.h5" % k)))
        last = ds["water_depth"].isel(time=-1).values
        assert last.shape == expected[0].shape
        assert np.array_equal(last, expected[0], equal_nan=True)
