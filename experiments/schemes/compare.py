#!/usr/bin/env python3
"""The three flow schemes on a real DEM (issue 16): pipes, local inertial and shallow water on
the same storm (erosion off: with Mei's capacity law and its defaults the shallow-water and the
pipes runs dig runaway pits thousands of metres deep at open edges, a problem of that law, issue
17, not of the flow), at the DEM's resolution and coarsened twice (dem.resample = 2), with
the shallow-water run as the reference. For each run: wall time, steps, water out through the
edges and its peak rate, flooded area (depth > 0.1 m), largest depth and speed, eroded and
deposited volumes (the final erosion field), and against the shallow-water run the depth
difference over the cells wet (> 1 cm) in either (RMS and 95th percentile) and how much of its
flooded area the scheme also floods. docs/experiments/schemes.md records a run.

Usage (from the repository root, after `bash scripts/setup.sh`):
  python3 experiments/schemes/compare.py tujunga [--backend opencl|cpu] [--factors 2,1]
Results go to out/schemes/<case>_<scheme>_r<factor>.h5 (replaced).
"""
import argparse
import importlib.util
import os
import subprocess
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _precision():
    """experiments/precision/compare.py: its binary path and storm, which this comparison
    shares."""
    spec = importlib.util.spec_from_file_location(
        "precision_compare", os.path.join(ROOT, "experiments", "precision", "compare.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_P = _precision()
ERODEM = _P.ERODEM
# the precision experiment's storm (50 mm/h for 1 h, adaptive steps, open edges) with erosion
# and thermal collapse off and a rougher bed
STORM = [s for s in _P.STORM if not s.startswith(("erosion.", "thermal."))] + [
    "erosion.enabled=false",
    "flow.manning_n=0.035",
]

CASES = {
    # one hour of 50 mm/h over the whole Big Tujunga tile (the precision experiment's storm)
    "tujunga": ("experiments/precision/tujunga.toml", STORM),
}
SCHEMES = ["shallow_water", "local_inertial", "pipes"]
WET, FLOODED = 0.01, 0.1  # m


def read(path):
    """The final depth (m), erosion (m), speed (m/s) and cell area (m^2), and the
    diagnostics' time and cumulative boundary outflow."""
    with h5py.File(path, "r") as f:
        h = f["water_depth"][-1].astype(np.float64)
        e = f["erosion"][-1].astype(np.float64)
        u = f["velocity_x"][-1].astype(np.float64)
        v = f["velocity_y"][-1].astype(np.float64)
        dx = abs(float(f["x"][1] - f["x"][0]))
        dy = abs(float(f["y"][1] - f["y"][0]))
        d = f["diagnostics"]
        t = d["time"][...]
        out = d["boundary_outflow_volume"][...]
    return h, e, np.hypot(u, v), dx * dy, t, out


def run(case, scheme, factor, backend, log):
    config, sets = CASES[case]
    os.makedirs(os.path.join(ROOT, "out", "schemes"), exist_ok=True)
    out = os.path.join(ROOT, "out", "schemes", "%s_%s_r%d.h5" % (case, scheme, factor))
    cmd = [ERODEM, "run", config, "--output", out, "--overwrite", "--backend", backend]
    for s in sets + ["flow.scheme=%s" % scheme, "output.restart_state=false",
                     "output.interval=1 h"]:
        cmd += ["--set", s]
    if factor > 1:
        cmd += ["--set", "dem.resample=%d" % factor]
    log("$ " + " ".join(cmd))
    start = time.time()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.time() - start
    if done.returncode != 0:
        log(done.stdout[-2000:] + done.stderr[-2000:])
        return None
    steps = None
    for line in done.stdout.splitlines() + done.stderr.splitlines():
        if line.startswith("ran ") and " steps" in line:
            steps = int(line.split()[1])
    return out, wall, steps


def summary(path, wall, steps):
    h, e, s, area, t, out = read(path)
    h = np.where(np.isfinite(h), h, 0.0)
    e = np.where(np.isfinite(e), e, 0.0)
    row = {
        "wall": wall,
        "steps": steps,
        "flooded_km2": float((h > FLOODED).sum() * area / 1e6),
        "max_depth": float(h.max()),
        "max_speed": float(np.nanmax(s)),
        "eroded": float(e[e > 0].sum() * area),
        "deposited": float(-e[e < 0].sum() * area),
    }
    if len(out) > 1:
        # the outflow rate over 60 s windows (steps differ between the schemes)
        grid = np.arange(0.0, t[-1] + 1e-9, 60.0)
        cum = np.interp(grid, t, out)
        rate = np.diff(cum) / 60.0
        row["out"] = float(out[-1])
        row["peak_out"] = float(rate.max())
        row["t_half"] = float(grid[1:][np.argmax(rate >= 0.5 * rate.max())])
    return row, h


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--backend", default="opencl")
    ap.add_argument("--factors", default="2,1")
    a = ap.parse_args()
    for factor in [int(x) for x in a.factors.split(",")]:
        rows, depths = {}, {}
        for scheme in SCHEMES:
            r = run(a.case, scheme, factor, a.backend, lambda s: print(s, flush=True))
            if r is None:
                print("%s failed" % scheme)
                continue
            rows[scheme], depths[scheme] = summary(*r)
        ref = depths.get("shallow_water")
        print("\n%s, resample factor %d, %s:" % (a.case, factor, a.backend))
        print("| scheme | wall (s) | steps | water out (m^3) | peak outflow (m^3/s) | outflow at half "
              "its peak (s) | flooded > 0.1 m (km^2) | max depth (m) | max speed (m/s) | RMS depth - "
              "sw (m) | 95th pct \\|depth - sw\\| (m) | sw flooded area also flooded |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for scheme, r in rows.items():
            cmp = ("", "", "")
            if ref is not None:
                h = depths[scheme]
                wet = (h > WET) | (ref > WET)
                dh = np.abs(h - ref)[wet]
                both = ((h > FLOODED) & (ref > FLOODED)).sum() / max(1, (ref > FLOODED).sum())
                cmp = ("%.3f" % np.sqrt(np.mean(dh ** 2)), "%.3f" % np.percentile(dh, 95),
                       "%.3f" % both)
            print("| %s | %.0f | %s | %.4g | %.4g | %.0f | %.3f | %.2f | %.2f | %s | %s | %s |"
                  % (scheme, r["wall"], r["steps"], r.get("out", float("nan")),
                     r.get("peak_out", float("nan")), r.get("t_half", float("nan")),
                     r["flooded_km2"], r["max_depth"], r["max_speed"], *cmp), flush=True)


if __name__ == "__main__":
    main()
