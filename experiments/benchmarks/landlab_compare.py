#!/usr/bin/env python3
"""erodem against Landlab's OverlandFlow: water only, the same grid, side by side.

Both run the local-inertial scheme of de Almeida et al. (2012) on one synthetic fBm terrain
(`erodem generate --kind fbm`, 10 m cells, 200 m relief) with 0.2 m of water on every cell
(all cells wet), 20 mm/h of rain, Manning n = 0.03 and a fixed step of 0.5 s. erodem runs
`erodem bench --dem` on that GeoTIFF with erosion, thermal collapse and evaporation off (the
full step of the bench: sources, flow, water update and the per-step statistics), local
inertial and pipes, float32 (and local inertial in float64, Landlab's precision), on
`--threads` threads of the CPU reference; Landlab 2.11 runs `OverlandFlow.run_one_step(dt)`
(numpy, one thread, float64; one sub-step per call at these depths, see below) in its own
virtual environment. The measurements alternate (erodem, Landlab, erodem, ...) so that the
machine's drift falls on both, and each figure is the median of `--repeats`.

Beside them runs a plain two-kernel pipe model (`pipes_plain.cpp` here, built with the system's
g++ into `build/pipes_plain`): the yardstick of issue 20's pipes target, on the same terrain,
depth, rain and step, with walls, as it is and with the velocities and the per-step volume sum
that erodem's step also computes (`--velocities --sums`).

Landlab's `overland_flow(dt)` takes sub-steps of min(alpha dx / sqrt(g h_max), dt): with
alpha = 0.7 and dx = 10 m, dt = 0.5 s is one sub-step while h_max < 19.9 m, which the worker
checks (it counts the sub-steps through the elapsed-time bookkeeping and refuses otherwise).

Usage (from the repository root, after building build/cli/erodem and build/python):
  python3 experiments/benchmarks/landlab_compare.py                 # 256 .. 8192, table + plot
  python3 experiments/benchmarks/landlab_compare.py --sizes 1024 --repeats 5
It needs g++ with OpenMP for the plain model (Debian's build-essential, which
scripts/setup.sh installs). The first run makes the virtual environment (build/landlab-venv:
landlab 2.11 and, for it on Python 3.11, requireit < 0.9, from PyPI). Writes a Markdown table
to stdout and to `--table`, and a plot of cell-steps/s against the grid size to `--plot`.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The scenario, shared by both sides (erodem's bench scenario with these keys set).
DT = 0.5  # s, fixed
DEPTH = 0.2  # m of water on every cell at the start
RAIN = 20e-3 / 3600  # m/s
MANNING = 0.03  # s/m^(1/3)
CELL = 10.0  # m
ERODEM_WATER_ONLY = [
    "erosion.enabled=false", "thermal.enabled=false", "evaporation.rate=0",
    "flow.manning_n=%g" % MANNING, "rain.rate=%.17g m/s" % RAIN,
]

WORKER = r'''
import json, sys, time
import numpy as np
from landlab import RasterModelGrid
from landlab.components import OverlandFlow
path, dt, depth, rain, manning, cell, min_seconds = sys.argv[1:8]
dt, depth, rain, manning, cell, min_seconds = map(float, (dt, depth, rain, manning, cell, min_seconds))
z = np.load(path)
grid = RasterModelGrid(z.shape, xy_spacing=cell)
grid.add_field("topographic__elevation", z.astype(np.float64).ravel(), at="node")
grid.add_field("surface_water__depth", np.full(z.size, depth), at="node")
of = OverlandFlow(grid, mannings_n=manning, rainfall_intensity=rain,
                  steep_slopes=False)
of.run_one_step(dt)  # warm-up: neighbour arrays, page faults
h0 = np.full(z.size, depth)
steps, elapsed, resets = 0, 0.0, 0
while True:
    # one sub-step per call while alpha dx / sqrt(g h_max) >= dt (alpha 0.7); where the
    # rain has deepened the water so far that it would not be, the state starts again from
    # the initial one (untimed)
    if of.calc_time_step() < dt:
        grid.at_node["surface_water__depth"][:] = h0
        grid.at_link["surface_water__discharge"][:] = 0.0
        resets += 1
        if of.calc_time_step() < dt:
            sys.exit("landlab: the CFL step is below dt at the initial state")
    start = time.perf_counter()
    of.run_one_step(dt)
    elapsed += time.perf_counter() - start
    steps += 1
    if elapsed >= min_seconds and steps >= 3:
        break
h = grid.at_node["surface_water__depth"]
print(json.dumps({"steps": steps, "seconds": elapsed, "resets": resets,
                  "cell_steps_per_second": z.size * steps / elapsed,
                  "max_depth": float(h.max()), "mean_depth": float(h.mean())}))
'''


def run(cmd, **kw):
    r = subprocess.run(cmd, text=True, capture_output=True, **kw)
    if r.returncode != 0:  # say what failed, with the child's own words
        sys.exit("%s: exit %d\n%s%s" % (" ".join(cmd), r.returncode, r.stdout[-2000:],
                                         r.stderr[-4000:]))
    return r


def ensure_venv(venv):
    py = os.path.join(venv, "bin", "python")
    try:
        run([py, "-c", "import landlab; assert landlab.__version__.startswith('2.11')"])
        return py
    except (OSError, subprocess.CalledProcessError):
        pass
    print("making %s (landlab 2.11 from PyPI) ..." % venv, file=sys.stderr)
    run([sys.executable, "-m", "venv", venv])
    run([py, "-m", "pip", "install", "-q", "landlab==2.11.*", "requireit<0.9"])
    return py


def ensure_plain(path):
    """Builds pipes_plain.cpp into `path` (again where the source is newer); returns `path`."""
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pipes_plain.cpp")
    if not os.path.exists(path) or os.path.getmtime(path) < os.path.getmtime(src):
        # erodem's value-safe kernel flags (kernels/CMakeLists.txt); the host's instructions
        run(["g++", "-std=c++17", "-O3", "-march=native", "-fopenmp", "-fno-math-errno",
             "-fno-trapping-math", "-ffp-contract=off", "-o", path, src])
    return path


def plain_rate(plain, f32, size, threads, steps, extra):
    """pipes_plain's median of three timed windows of `steps` steps, as erodem bench's."""
    cmd = [plain, f32, str(size), str(size), str(CELL), str(steps), "--depth", str(DEPTH),
           "--rain", "%.17g" % RAIN, "--dt", str(DT), "--repeats", "3"] + extra
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    return json.loads(run(cmd, env=env).stdout)["cell_steps_per_second"]


def make_terrain(erodem, size, folder):
    """The fBm GeoTIFF of `size`^2 cells and its elevations as a .npy (through erodem's reader)."""
    tif = os.path.join(folder, "fbm_%d.tif" % size)
    run([erodem, "generate", "--kind", "fbm", "--size", str(size), "--seed", "1", "--relief",
         "200", "--cell-size", str(CELL), "--overwrite", tif])
    sys.path.insert(0, os.path.join(ROOT, "build", "python"))
    import erodem as ed  # noqa: E402  (the build tree's module)
    import numpy as np
    z = np.asarray(ed.read_dem(tif).elevation, dtype=np.float64)
    npy = os.path.join(folder, "fbm_%d.npy" % size)
    np.save(npy, z)
    f32 = os.path.join(folder, "fbm_%d.f32" % size)  # for pipes_plain
    z.astype(np.float32).tofile(f32)
    return tif, npy, f32


def erodem_rate(erodem, tif, threads, steps, extra):
    cmd = [erodem, "bench", "--dem", tif, "--steps", str(steps), "--backends", "cpu",
           "--threads", str(threads), "--stream-floats", "1000000", "--json"]
    for s in ERODEM_WATER_ONLY + extra:
        cmd += ["--set", s]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    out = json.loads(run(cmd, env=env).stdout)
    (row,) = [r for r in out["results"] if r["process"] == "full_step"]
    return row["cell_steps_per_second"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="256,512,1024,2048,4096,8192")
    ap.add_argument("--landlab-max", type=int, default=4096,
                    help="largest grid Landlab runs (its link arrays: ~1.5 kB per cell)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=3.0,
                    help="least time of one Landlab measurement (s)")
    ap.add_argument("--erodem", default=os.path.join(ROOT, "build", "cli", "erodem"))
    ap.add_argument("--venv", default=os.path.join(ROOT, "build", "landlab-venv"))
    ap.add_argument("--table", default=os.path.join(ROOT, "build", "landlab_compare.md"))
    ap.add_argument("--plot", default=os.path.join(ROOT, "build", "landlab_compare.png"))
    ap.add_argument("--json", default=os.path.join(ROOT, "build", "landlab_compare.json"))
    ap.add_argument("--plain", default=os.path.join(ROOT, "build", "pipes_plain"),
                    help="where pipes_plain.cpp is built")
    a = ap.parse_args()
    sizes = [int(s) for s in a.sizes.split(",")]
    py = ensure_venv(a.venv)
    plain = ensure_plain(a.plain)
    runs = {  # name -> (how, erodem's extra --set values or pipes_plain's extra options)
        "erodem local inertial f32": ("erodem", []),
        "erodem pipes f32": ("erodem", ["flow.scheme=pipes"]),
        "erodem local inertial f64": ("erodem", ["numerics.precision=float64"]),
        "landlab OverlandFlow f64": ("landlab", None),
        "plain pipes f32": ("plain", []),
        "plain pipes f32 + velocities + sums": ("plain", ["--velocities", "--sums"]),
    }
    results = {name: {} for name in runs}
    with tempfile.TemporaryDirectory() as tmp:
        worker = os.path.join(tmp, "worker.py")
        with open(worker, "w") as f:
            f.write(WORKER)
        for n in sizes:
            tif, npy, f32 = make_terrain(a.erodem, n, tmp)
            steps = max(3, min(50, int(2e8 / (n * n))))
            samples = {name: [] for name in runs}
            for _ in range(a.repeats):
                for name, (how, extra) in runs.items():
                    if how == "erodem":
                        samples[name].append(erodem_rate(a.erodem, tif, a.threads, steps, extra))
                    elif how == "plain":
                        samples[name].append(plain_rate(plain, f32, n, a.threads, steps, extra))
                    elif n <= a.landlab_max:
                        out = json.loads(run([py, worker, npy, str(DT), str(DEPTH), str(RAIN),
                                              str(MANNING), str(CELL), str(a.seconds)]).stdout)
                        samples[name].append(out["cell_steps_per_second"])
            for name in runs:
                if samples[name]:
                    results[name][n] = statistics.median(samples[name])
            print("%6d^2: " % n + ", ".join("%s %.3g" % (k, v[n]) for k, v in results.items()
                                             if n in v), file=sys.stderr)
            os.remove(tif)
            os.remove(npy)
            os.remove(f32)
    lines = ["| grid | " + " | ".join(runs) + " | local inertial / Landlab | erodem pipes / plain "
             "pipes |", "|---" * (len(runs) + 3) + "|"]
    for n in sizes:
        ll = results["landlab OverlandFlow f64"].get(n)
        li = results["erodem local inertial f32"].get(n)
        ep, pp = results["erodem pipes f32"].get(n), results["plain pipes f32"].get(n)
        cells = ["%.3g" % results[k][n] if n in results[k] else "—" for k in runs]
        ratio = "%.1f×" % (li / ll) if ll and li else "—"
        pipes = "%.2f" % (ep / pp) if ep and pp else "—"
        lines.append("| %d² | %s | %s | %s |" % (n, " | ".join(cells), ratio, pipes))
    table = "\n".join(lines)
    header = ("cell-steps/s, median of %d alternating runs; erodem CPU reference on %d threads "
              "(full step, water only), Landlab %s on 1 thread (numpy), the plain pipes "
              "(pipes_plain.cpp) on the same threads\n\n"
              % (a.repeats, a.threads, "2.11"))
    print(header + table)
    with open(a.table, "w") as f:
        f.write(header + table + "\n")
    with open(a.json, "w") as f:
        json.dump({"sizes": sizes, "threads": a.threads, "repeats": a.repeats,
                   "created": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                   "results": {k: {str(n): v for n, v in r.items()} for k, r in results.items()}},
                  f, indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: no plot", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for name, r in results.items():
        ns = sorted(r)
        ax.loglog([n * n for n in ns], [r[n] for n in ns], "o-", label=name)
    ax.set_xlabel("cells")
    ax.set_ylabel("cell-steps per second")
    ax.set_title("Water only, fixed dt, all cells wet (%d threads for erodem and the plain pipes)"
                 % a.threads)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.plot, dpi=110)
    print("plot: %s" % a.plot, file=sys.stderr)


if __name__ == "__main__":
    main()
