"""Flow speeds against Manning's normal-flow speed on every real DEM of ../shared/data/dem.

A storm (50 mm/h, 1 h by default) with erosion at its defaults runs on a crop of each DEM,
local inertial, open edges, the adaptive step. Every `--every` seconds of simulated time each
wet cell (depth >= numerics.velocity_min_depth, where the model computes a velocity) is
compared with the speed uniform flow of its depth would have on its steepest water-surface
slope:

    V_n = h^(2/3) S^(1/2) / n,   S = the largest |eta_a - eta_b| / distance over its four faces

(the largest slope errs in the scheme's favour). A cell counts as too fast when its speed
exceeds 1.5 V_n (issue 14) and 0.1 m/s: on nearly flat water (ponds, the sea) V_n is a few
mm/s and slow circulation of a few cm/s is inertia, not the artefact, which runs at dx/dt
(6 m/s and more at 30 m cells and 5 s steps). The table gives how many cell samples were too
fast, of how many wet ones, the largest ratio among cells faster than 0.1 m/s, how many
cells ever ran faster than 0.5 dx/dt, and the largest speed. Each crop runs twice, with time.dt_max = 5 s and 2.5 s,
and the table gives the change of the eroded volume between the two.

Usage (from the repository root, after `bash scripts/setup.sh`):
    PYTHONPATH=build/python python3 experiments/thin_film/speeds.py [--duration 3600]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

import erodem

# ../shared/data/dem beside the repository root
DEM_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared",
                        "data", "dem")

# name: (path under DEM_ROOT, window [col, row, width, height] or None, read_dem settings)
CROPS = {
    "volcano": ("volcano/volcano_northup_10m.tif", None, {"cell_size": 10.0}),
    "big_tujunga": ("big_tujunga/srtm_bigtujunga30m_utm11.tif", [600, 200, 256, 256], {}),
    "puget_sound": (
        "puget_sound/ps_height_1k.png",
        [500, 600, 256, 256],
        {"cell_size": 160.0, "z_scale": 0.1},
    ),
    "boulder": ("boulder/srtm_gl3_boulder.asc", [0, 250, 256, 256], {"crs": "EPSG:4326"}),
    "rhine": ("rhine/rhine_elv0.tif", [300, 420, 256, 256], {}),
    "eno": ("eno/enogeo.tif", [200, 300, 256, 256], {}),
    "dfw": ("dfw/dfw_srtm3.tif", [50, 50, 256, 256], {}),
}

MANNING_N = 0.03  # flow.manning_n's default (s m^-1/3)
TOO_FAST = 1.5  # the issue's bound on speed / V_n
SLOW = 0.1  # m/s: slower cells are not counted (see the docstring)


def steepest_surface_slope(eta: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Largest |d eta| / distance over the four faces of every cell (NaN neighbours skipped)."""
    s = np.zeros_like(eta)
    ex = np.abs(np.diff(eta, axis=1)) / dx[:, None]
    ey = np.abs(np.diff(eta, axis=0)) / (0.5 * (dy[:-1] + dy[1:]))[:, None]
    ex = np.nan_to_num(ex, nan=0.0)
    ey = np.nan_to_num(ey, nan=0.0)
    s[:, :-1] = np.maximum(s[:, :-1], ex)
    s[:, 1:] = np.maximum(s[:, 1:], ex)
    s[:-1, :] = np.maximum(s[:-1, :], ey)
    s[1:, :] = np.maximum(s[1:, :], ey)
    return s


def run(dem, backend: str, duration: float, dt_max: float, every: float) -> dict:
    sim = erodem.Simulation(
        dem,
        backend=backend,
        rain__rate="50 mm/h",
        erosion__enabled=True,
        erosion__law="mei",
        boundary__north="open",
        boundary__south="open",
        boundary__east="open",
        boundary__west="open",
        time__duration=duration,
        time__adaptive=True,
        time__dt_max=dt_max,
    )
    min_depth = 1e-3  # numerics.velocity_min_depth's default (m)
    dx = np.asarray(dem.dx, dtype=np.float64)
    dy = np.asarray(dem.dy, dtype=np.float64)
    fast = samples = over_half_dx_dt = 0
    worst_ratio = worst_speed = 0.0
    next_sample = every
    start = time.perf_counter()
    while not sim.finished:
        sim.step()
        if sim.time + 1e-9 < next_sample and not sim.finished:
            continue
        next_sample += every
        h = np.asarray(sim.water_depth, dtype=np.float64)
        eta = np.asarray(sim.bed, dtype=np.float64) + h
        eta[~dem.mask] = np.nan
        speed = np.hypot(np.asarray(sim.velocity_x), np.asarray(sim.velocity_y))
        wet = (h >= min_depth) & dem.mask
        s = steepest_surface_slope(eta, dx, dy)
        v_n = np.power(h, 2.0 / 3.0) * np.sqrt(s) / MANNING_N
        moving = wet & (speed > SLOW)
        ratio = np.where(moving & (v_n > 0), speed / np.where(v_n > 0, v_n, 1.0), 0.0)
        ratio[moving & (v_n <= 0)] = np.inf
        fast += int(np.count_nonzero(ratio > TOO_FAST))
        dt = sim.diagnostics["dt"]
        over_half_dx_dt += int(np.count_nonzero(wet & (speed > 0.5 * dx[:, None] / dt)))
        samples += int(np.count_nonzero(wet))
        worst_ratio = max(worst_ratio, float(ratio.max(initial=0.0)))
        worst_speed = max(worst_speed, float(np.where(wet, speed, 0.0).max(initial=0.0)))
    eroded, deposited = sim.erosion_volumes()
    return dict(
        fast=fast,
        samples=samples,
        over_half_dx_dt=over_half_dx_dt,
        worst_ratio=worst_ratio,
        worst_speed=worst_speed,
        eroded=eroded,
        deposited=deposited,
        steps=sim.steps_done,
        seconds=time.perf_counter() - start,
    )


def measure(name: str, duration: float, every: float = 60.0, backend: str = "cpu",
            window=None) -> dict:
    """Both runs of crop `name` (window: replaces the crop's) and the eroded volume's change."""
    path, crop, settings = CROPS[name]
    dem = erodem.read_dem(os.path.join(DEM_ROOT, path), window=window or crop, **settings)
    a = run(dem, backend, duration, 5.0, every)
    b = run(dem, backend, duration, 2.5, every)
    change = (b["eroded"] - a["eroded"]) / a["eroded"] if a["eroded"] > 0 else float("nan")
    return dict(shape=dem.shape, dt_max_5=a, dt_max_2_5=b, eroded_change=change)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=3600.0, help="storm length (s)")
    ap.add_argument("--every", type=float, default=60.0, help="sampling interval (s)")
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--only", nargs="*", default=None, help="crop names")
    args = ap.parse_args()
    print(
        "| DEM | cells | dt_max 5 s: samples > 1.5 V_n and 0.1 m/s / wet samples "
        "| largest speed / V_n | samples > 0.5 dx/dt | largest speed (m/s) | eroded (m^3) "
        "| eroded with dt_max 2.5 s | change |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name in CROPS:
        if args.only and name not in args.only:
            continue
        m = measure(name, args.duration, args.every, args.backend)
        a, b = m["dt_max_5"], m["dt_max_2_5"]
        print(
            f"| {name} | {m['shape'][1]} x {m['shape'][0]} | {a['fast']} / {a['samples']} "
            f"({a['fast'] / max(a['samples'], 1):.2%}) | {a['worst_ratio']:.3g} "
            f"| {a['over_half_dx_dt']} | {a['worst_speed']:.3g} | {a['eroded']:.4g} "
            f"| {b['eroded']:.4g} | {m['eroded_change']:+.2%} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
