"""The overhead of the Python layer against the CLI on the same run (docs/python.md).

Runs the same config (Big Tujunga, a 512 x 512 window, erosion + transport + thermal, a
result file with snapshots every 100 steps) with ``erodem run`` and with
``erodem.Simulation(config=...).run(output=...)``, each as its own process, interleaved
(CLI, Python, CLI, Python, ...), and prints the wall times, their medians and spread, and
the overhead of the medians. Usage (from the repository root):

    ERODEM_BUILD_DIR=build python3 tests/python/bench_overhead.py [--repeats 3] [--steps 300]
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.path.join(REPO, os.environ.get("ERODEM_BUILD_DIR", "build"))
DEM = os.path.abspath(
    os.path.join(REPO, "..", "shared", "data", "dem", "big_tujunga", "srtm_bigtujunga30m_utm11.tif")
)

CONFIG = """
[dem]
path = "{dem}"
window = [0, 0, 512, 512]
[initial]
water_depth = 0.01
[time]
steps = {steps}
adaptive = true
cfl = 0.7
dt_max = "2 s"
[rain]
rate = "60 mm/h"
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.02
dissolving_rate = 0.005
deposition_rate = 0.02
min_tilt = 0.02
[thermal]
enabled = true
talus_angle = 45.0
rate = 0.001
[boundary]
east = "open"
south = "open"
[output]
every = 100
[numerics]
threads = {threads}
"""

PY = """
import sys, time, erodem
sim = erodem.Simulation(config=sys.argv[1], backend=sys.argv[3])
t0 = time.perf_counter()
sim.run(output=sys.argv[2])
print("ran %d steps in %.6f s wall" % (sim.steps_done, time.perf_counter() - t0))
"""


def timed(cmd, env):
    """Wall time (s) and CPU time (user + system, s) of one run of ``cmd``, and the wall time
    of its stepping loop as it reports it ("... in X s wall": the CLI's loop with the result
    writer, from after the first snapshot to after the last; Python's sim.run(output=...),
    which also includes opening the file and the first snapshot)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         text=True)
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise SystemExit("%s exited %d" % (cmd, p.returncode))
    loop = float(re.search(r" in ([0-9.]+) s wall", out).group(1))
    return wall, usage.ru_utime + usage.ru_stime, loop


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--backend", default="cpu")
    a = ap.parse_args()
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(BUILD, "python")
    tmp = tempfile.mkdtemp(prefix="erodem-overhead-")
    cfg = os.path.join(tmp, "cfg.toml")
    with open(cfg, "w") as f:
        f.write(CONFIG.format(dem=DEM, steps=a.steps, threads=a.threads))
    runs = {"cli": [], "python": []}
    for i in range(a.repeats):
        out = os.path.join(tmp, "cli%d.h5" % i)
        runs["cli"].append(timed([os.path.join(BUILD, "cli", "erodem"), "run", cfg, "--backend",
                                  a.backend, "--output", out], env))
        out = os.path.join(tmp, "py%d.h5" % i)
        runs["python"].append(timed([sys.executable, "-c", PY, cfg, out, a.backend], env))
        print("repeat %d: cli %.3f s wall %.3f s cpu %.3f s loop, python %.3f s wall %.3f s "
              "cpu %.3f s loop" % ((i,) + runs["cli"][-1] + runs["python"][-1]), flush=True)
    print("512 x 512, %d steps, backend %s, %d thread(s), %d repeats" % (a.steps, a.backend,
                                                                          a.threads, a.repeats))
    med = {}
    for what, k in (("wall", 0), ("cpu", 1), ("loop", 2)):
        for name in ("cli", "python"):
            v = [r[k] for r in runs[name]]
            med[name, what] = statistics.median(v)
            print("%-6s %-4s median %.3f s  (min %.3f, max %.3f)" % (name, what, med[name, what],
                                                                    min(v), max(v)))
        print("overhead of the %s medians: %+.2f %%" % (
            what, 100.0 * (med["python", what] - med["cli", what]) / med["cli", what]))


if __name__ == "__main__":
    main()
