#!/usr/bin/env python3
"""Resident bytes per cell of each configuration (flow scheme x erosion x precision x backend).

Runs `erodem run` on a synthetic fBm terrain of N^2 cells for a few steps, writing a result
file as a run does (one snapshot at the start and one at the end), and reads the peak
resident set of the process (`ru_maxrss` of the child: Linux's VmHWM, setup, steps and output
included). The same run on a 64^2 grid gives the fixed part (the program, its libraries,
PoCL's compiler); (peak(N) - peak(64)) / (N^2 - 64^2) is the resident bytes per cell. On PoCL
the OpenCL buffers live in host memory, so they are in the figure too.

Usage (from the repository root, after building build/cli/erodem):
  python3 experiments/benchmarks/memory.py                  # 2048^2, every configuration
  python3 experiments/benchmarks/memory.py --size 4096 --backends cpu
  # the 16385^2 run of docs/performance.md (about 22 GiB, 5 minutes on 2 cores): the default
  # erosion configuration, the depth alone written, no restart state
  python3 experiments/benchmarks/memory.py --size 16385 --backends cpu --precisions float32 \
      --schemes local_inertial --erosion on --light-output
Prints a Markdown table (docs/performance.md, "Resident memory").
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CONFIG = """[dem]
synthetic = "fbm"
size = {size}
seed = 1
relief = "200 m"
cell_size = "10 m"
[time]
steps = {steps}
adaptive = false
dt = "0.5 s"
[initial]
water_depth = "0.2 m"
[rain]
rate = "20 mm/h"
[flow]
scheme = "{scheme}"
[erosion]
enabled = {erosion}
[thermal]
enabled = {erosion}
[numerics]
precision = "{precision}"
[output]
path = "{output}"
every = {steps}
{light}"""

SCHEMES = ["pipes", "local_inertial", "shallow_water"]


def peak_rss(erodem, folder, size, steps, scheme, erosion, precision, backend, light=False):
    """The child's peak resident set (bytes) for one run; `light`: the depth alone written,
    without the restart state (a run whose output would otherwise take longer than its steps)."""
    output = os.path.join(folder, "m.h5")
    cfg = os.path.join(folder, "m.toml")
    with open(cfg, "w") as f:
        f.write(CONFIG.format(size=size, steps=steps, scheme=scheme,
                              erosion="true" if erosion else "false", precision=precision,
                              output=output,
                              light='fields = ["water_depth"]\nrestart_state = false\n'
                              if light else ""))
    env = dict(os.environ, OMP_NUM_THREADS="2")
    # Each run in a fresh child of a fresh helper: RUSAGE_CHILDREN keeps the largest child
    # seen so far, so a small run after a large one would read the large one's peak.
    r = subprocess.run([sys.executable, "-c",
                        "import resource, subprocess, sys; "
                        "p = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, "
                        "stderr=subprocess.PIPE, text=True); "
                        "sys.stderr.write(p.stderr if p.returncode else ''); "
                        "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss); "
                        "sys.exit(p.returncode)",
                        erodem, "run", cfg, "--backend", backend, "--overwrite"],
                       capture_output=True, text=True, env=env)
    if r.returncode != 0:
        raise SystemExit("erodem run failed (%s, %s, erosion %s, %s, %s): %s"
                         % (size, scheme, erosion, precision, backend, r.stderr.strip()))
    return int(r.stdout.strip()) * 1024  # ru_maxrss is in KiB on Linux


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=2048)
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--backends", default="cpu,opencl")
    ap.add_argument("--erodem", default=os.path.join(ROOT, "build", "cli", "erodem"))
    ap.add_argument("--schemes", default=",".join(SCHEMES))
    ap.add_argument("--precisions", default="float32,float64")
    ap.add_argument("--erosion", choices=["off", "on", "both"], default="both",
                    help="erosion + thermal off, on, or both runs")
    ap.add_argument("--light-output", action="store_true",
                    help="write the depth alone and no restart state")
    a = ap.parse_args()
    cells = a.size * a.size - 64 * 64
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for backend in a.backends.split(","):
            for precision in a.precisions.split(","):
                if backend == "opencl" and precision == "float64":
                    continue  # the OpenCL kernels are float32
                for scheme in a.schemes.split(","):
                    for erosion in {"off": (False,), "on": (True,), "both": (False, True)}[a.erosion]:
                        base = peak_rss(a.erodem, folder, 64, a.steps, scheme, erosion,
                                        precision, backend, a.light_output)
                        big = peak_rss(a.erodem, folder, a.size, a.steps, scheme, erosion,
                                       precision, backend, a.light_output)
                        per_cell = (big - base) / cells
                        rows.append((backend, precision, scheme, erosion, big, per_cell))
                        print("%-6s %-7s %-14s erosion %-5s peak %7.1f MiB  %6.1f B/cell"
                              % (backend, precision, scheme, erosion, big / 2**20, per_cell),
                              file=sys.stderr)
    print("Peak resident bytes per cell, `erodem run` of %d steps on %d² cells with one "
          "snapshot written at the start and the end (%s)\n"
          % (a.steps, a.size, time.strftime("%Y-%m-%d", time.gmtime())))
    print("| backend | precision | flow scheme | erosion + thermal | peak RSS (MiB) | B/cell |")
    print("|---|---|---|---|---|---|")
    for backend, precision, scheme, erosion, big, per_cell in rows:
        print("| %s | %s | %s | %s | %.0f | %.1f |" % (backend, precision, scheme,
                                                    "on" if erosion else "off", big / 2**20,
                                                    per_cell))


if __name__ == "__main__":
    main()
