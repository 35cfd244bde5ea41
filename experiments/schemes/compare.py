#!/usr/bin/env python3
"""The three flow schemes on the real DEMs (issue 16): pipes, local inertial and shallow water
on the same storm, at the DEM's resolution and coarsened twice (dem.resample = 2), with the
shallow-water run as the reference. Two cases: the Puget Sound storm (the main job,
experiments/puget_sound/config.toml, its storm and edges as they are) and one hour of 50 mm/h
over Big Tujunga (the precision experiment's storm). The hydraulic runs have erosion and slope
collapse off: with Mei's capacity law and its defaults the shallow-water and the pipes runs dig
runaway pits at open edges, a problem of that law (issue 17), not of the flow.

For each run: wall time, steps, the water ledger's closure, water out through the edges (and
the sea) and its peak rate, flooded area (depth > 0.1 m) at the end and the largest over the
snapshots, largest depth and speed, and against the shallow-water run the final depth
difference over the cells wet (> 1 cm) in either (RMS and 95th percentile) and how much of
its flooded area the scheme also floods. Each case has four gauges (output.gauges): per
scheme their peak depth, its time, the time the depth first reaches half of it and the peak
speed, a hydrograph figure, and maps of the final depth differences (local inertial - shallow
water, pipes - shallow water) at the DEM's resolution. With --erosion, each scheme also runs
once at resample 2 with erosion on (the case's own erosion settings: Puget Sound's
scaled-down constants, Big Tujunga's defaults, slope collapse on in both): eroded and
deposited volumes from the final erosion field, the deepest bed change, how much of the
eroded volume lies in pits deeper than PIT m and at the edges, and the ledger's volumes of
the flow's erosion alone. docs/experiments/schemes.md records a run.

Usage (from the repository root, after `bash scripts/setup.sh`, or with a binary built
elsewhere through --erodem or the ERODEM environment variable):
  python3 experiments/schemes/compare.py puget [--backend cpu|opencl] [--factors 1,2]
      [--erosion] [--erodem PATH] [--figures docs/experiments] [--reuse]
  python3 experiments/schemes/compare.py tujunga ...
Results go to out/schemes/<case>_<scheme>_r<factor>[_erosion].h5 (replaced), with the wall
time and steps of each run in a .json beside it; --reuse reads those instead of running again
(to redraw the tables and figures). Figures: <figures>/schemes_<case>_gauges.png and
<figures>/schemes_<case>_depth_diff.png.
"""
import argparse
import importlib.util
import json
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
OFF = ["erosion.enabled=false", "thermal.enabled=false"]
# the precision experiment's storm (50 mm/h for 1 h, adaptive steps, open edges) with a rougher
# bed; the hydraulic runs without erosion and thermal collapse, the erosion runs with the
# erosion defaults (Mei's law) and thermal collapse on, as the precision experiment has them
TUJUNGA_ON = _P.STORM + ["flow.manning_n=0.035"]
STORM = [s for s in TUJUNGA_ON if not s.startswith(("erosion.", "thermal."))] + OFF

# Gauges (x, y in the DEM's CRS: UTM 11N for Big Tujunga, local metres for Puget Sound),
# chosen on the DEM at its resolution: D8 drainage areas of the pit-filled DEM and the
# channels and ponds of a shallow-water run of the case. Each is the centre of a cell at the
# DEM's resolution. Coarsened, a one-cell channel moves by a cell or two: at resample f each
# gauge is sampled in the 5 x 5 coarse cells around it (SNAP), and the one where the
# shallow-water run peaks highest stands for it in every scheme (`snap`): the peak unit
# discharge (depth x speed) for a channel gauge, the peak depth for a pond.
CASES = {
    # the main job's storm: 45 mm over 2 h peaking at 30 mm/h, followed for 1 h more, over
    # 1025 x 1025 cells of 160 m; fixed-level edges and the sea at 0 m
    "puget": {
        "config": "experiments/puget_sound/config.toml",
        "hydraulic": OFF,
        "erosion": [],
        "interval": "15 min",
        "dx": 160.0,  # m, the DEM's cell size
        "gauges": [
            ("river NW of Mt Rainier (130 km2, 542 m)", 117200.0, 95600.0, "channel"),
            ("steep channel, Rainier S flank (13 km2, 1352 m)", 129520.0, 72560.0, "channel"),
            ("lowland river W of Rainier (595 km2, 372 m)", 96720.0, 68240.0, "channel"),
            ("floodplain pond (763 km2, 302 m)", 86640.0, 73200.0, "pond"),
        ],
    },
    # one hour of 50 mm/h over the whole Big Tujunga tile (1197 x 643 cells of 30 m)
    "tujunga": {
        "config": "experiments/precision/tujunga.toml",
        "hydraulic": STORM,
        "erosion": TUJUNGA_ON,
        "interval": "10 min",
        "dx": 30.0,
        "gauges": [
            ("main stem near the outlet (291 km2, 428 m)", 380648.655, 3794192.828, "channel"),
            ("main channel, mid-basin (57 km2, 880 m)", 394748.655, 3797432.828, "channel"),
            ("tributary from the north (7.6 km2, 1110 m)", 396698.655, 3801062.828, "channel"),
            ("low point in the lowland fan (396 m)", 379148.655, 3793352.828, "pond"),
        ],
    },
}
SCHEMES = ["shallow_water", "local_inertial", "pipes"]
COLORS = {"shallow_water": "black", "local_inertial": "tab:blue", "pipes": "tab:red"}
WET, FLOODED = 0.01, 0.1  # m
PIT = 10.0  # m: a cell eroded deeper than this counts as a pit
SNAP = 2  # coarse cells each side of a gauge searched at resample > 1


def output_path(case, scheme, factor, erosion):
    return os.path.join(ROOT, "out", "schemes", "%s_%s_r%d%s.h5"
                        % (case, scheme, factor, "_erosion" if erosion else ""))


def read(path):
    """The final depth (m), erosion (m), speed (m/s) and bed (m), the cell area (m^2), the
    depth at every snapshot, the diagnostics' time and cumulative boundary outflow, and the
    last relative water closure."""
    with h5py.File(path, "r") as f:
        depths = f["water_depth"][...].astype(np.float64)
        e = f["erosion"][-1].astype(np.float64)
        u = f["velocity_x"][-1].astype(np.float64)
        v = f["velocity_y"][-1].astype(np.float64)
        bed = f["bed"][0].astype(np.float64)
        area = float(f["cell_area"][0])
        d = f["diagnostics"]
        t = d["time"][...]
        out = d["boundary_outflow_volume"][...]
        closure = float(d["relative_closure_error"][-1])
    return depths[-1], e, np.hypot(u, v), bed, area, depths, t, out, closure


def gauge_points(case, factor):
    """The points given to output.gauges: the case's gauges at factor 1, and the coarse
    cells within SNAP of each (row by row from the north-west) at factor > 1."""
    c = CASES[case]
    if factor == 1:
        return [(x, y) for _, x, y, _ in c["gauges"]]
    d = factor * c["dx"]
    return [(x + i * d, y + j * d) for _, x, y, _ in c["gauges"]
            for j in range(SNAP, -SNAP - 1, -1) for i in range(-SNAP, SNAP + 1)]


def gauges(path):
    """Per gauge point: the time (s), depth (m) and speed (m/s) series."""
    with h5py.File(path, "r") as f:
        g = f["gauges"]
        t = g["time"][...]
        return [(t, g["water_depth"][:, i], g["speed"][:, i]) for i in range(len(g["x"]))]


def snap(case, series, factor):
    """At factor > 1, keeps for each gauge the one of its points where the shallow-water
    run peaks highest (unit discharge for a channel, depth for a pond), in every scheme's
    series; returns the chosen (row, column) in each gauge's (2 SNAP + 1)^2 block."""
    if factor == 1:
        return None
    ref = series[("shallow_water", factor)]
    n = (2 * SNAP + 1) ** 2
    pick = []
    for i, (_, _, _, kind) in enumerate(CASES[case]["gauges"]):
        peak = [(d * s if kind == "channel" else d).max() for _, d, s in ref[n * i:n * i + n]]
        pick.append(n * i + int(np.argmax(peak)))
    for key in [k for k in series if k[1] == factor]:
        series[key] = [series[key][p] for p in pick]
    return [divmod(p % n, 2 * SNAP + 1) for p in pick]


def run(case, scheme, factor, backend, erodem, log, erosion=False, reuse=False):
    """Runs one scheme of a case (or, with reuse, takes the stored run); returns the result
    path, wall time (s) and steps."""
    c = CASES[case]
    os.makedirs(os.path.join(ROOT, "out", "schemes"), exist_ok=True)
    out = output_path(case, scheme, factor, erosion)
    meta = out[:-3] + ".json"
    if reuse and os.path.exists(out) and os.path.exists(meta):
        with open(meta) as f:
            m = json.load(f)
        return out, m["wall"], m["steps"]
    gauge_list = "[%s]" % ", ".join("[%.3f, %.3f]" % p for p in gauge_points(case, factor))
    sets = (c["erosion"] if erosion else c["hydraulic"]) + [
        "flow.scheme=%s" % scheme, "output.restart_state=false",
        "output.interval=%s" % c["interval"], "output.gauges=%s" % gauge_list]
    if factor > 1:
        sets.append("dem.resample=%d" % factor)
    cmd = [erodem, "run", c["config"], "--output", out, "--overwrite", "--backend", backend]
    for s in sets:
        cmd += ["--set", s]
    log("$ " + " ".join(cmd))
    start = time.time()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.time() - start
    if done.returncode != 0:
        log("exit %d\n%s%s" % (done.returncode, done.stdout[-2000:], done.stderr[-2000:]))
        return None
    steps = None
    for line in done.stdout.splitlines() + done.stderr.splitlines():
        if line.startswith("ran ") and " steps" in line:
            steps = int(line.split()[1])
    with open(meta, "w") as f:
        json.dump({"wall": wall, "steps": steps, "command": cmd}, f)
    return out, wall, steps


def summary(path, wall, steps):
    """The table row of one run, and its final depth (inactive cells 0)."""
    h, e, s, bed, area, depths, t, out, closure = read(path)
    active = np.isfinite(bed)
    bad = int((~np.isfinite(h) & active).sum() + (~np.isfinite(s) & active).sum())
    h = np.where(np.isfinite(h), h, 0.0)
    flooded = [float((np.nan_to_num(d) > FLOODED).sum() * area / 1e6) for d in depths]
    row = {
        "wall": wall,
        "steps": steps,
        "closure": closure,
        "nonfinite": bad,
        "flooded_km2": flooded[-1],
        "flooded_max_km2": max(flooded),
        "max_depth": float(h.max()),
        "max_speed": float(np.nanmax(s)),
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


def erosion_summary(path, wall, steps):
    """Eroded and deposited volumes (m^3) of the final erosion field, the deepest erosion and
    deposition (m), the share of the eroded volume in pits deeper than PIT and of that in
    pits within 3 cells of a map edge, the number of pits, the ledger's gross volumes of the
    flow's erosion and deposition alone (the erosion field also holds slope collapse), and
    the ledger's material closure."""
    h, e, s, bed, area, depths, t, out, closure = read(path)
    with h5py.File(path, "r") as f:
        d = f["diagnostics"]
        mat = float(d["relative_material_closure_error"][-1])
        gross = (float(d["eroded_volume"][-1]), float(d["deposited_volume"][-1]))
    active = np.isfinite(bed)
    bad = int((~np.isfinite(e) & active).sum())
    e = np.where(np.isfinite(e), e, 0.0)
    eroded = e[e > 0].sum() * area
    pit = e > PIT
    edge = np.zeros_like(pit)
    edge[:3, :] = edge[-3:, :] = edge[:, :3] = edge[:, -3:] = True
    return {
        "wall": wall, "steps": steps, "nonfinite": bad, "closure": closure,
        "material_closure": mat, "gross": gross,
        "eroded": float(eroded), "deposited": float(-e[e < 0].sum() * area),
        "max_erosion": float(e.max()), "max_deposition": float(-e.min()),
        "pits": int(pit.sum()),
        "pit_share": float(e[pit].sum() * area / eroded) if eroded > 0 else 0.0,
        "edge_pit_share": float(e[pit & edge].sum() * area / eroded) if eroded > 0 else 0.0,
    }


def gauge_table(case, series):
    """Peak depth (m), its time and the time the depth first reaches half of it (min; the
    peak's time is loose on a plateau), and the peak speed (m/s) per gauge and scheme, for
    each factor. series: {(scheme, factor): [(t, depth, speed), ...]}."""
    factors = sorted({f for _, f in series})
    head = "| gauge | scheme |" + "".join(
        " peak depth r%d (m) | time of peak r%d (min) | half peak r%d (min) | peak speed r%d "
        "(m/s) |" % (f, f, f, f) for f in factors)
    print(head)
    print("|---|---|" + "---|---|---|---|" * len(factors))
    for i, (name, _, _, _) in enumerate(CASES[case]["gauges"]):
        for scheme in SCHEMES:
            cells = []
            for f in factors:
                g = series.get((scheme, f))
                if g is None:
                    cells.append(" | | | ")
                    continue
                t, d, s = g[i]
                k = int(np.argmax(d))
                half = t[int(np.argmax(d >= 0.5 * d[k]))]
                cells.append("%.2f | %.0f | %.0f | %.2f"
                             % (d[k], t[k] / 60.0, half / 60.0, np.max(s)))
            print("| %s | %s | %s |" % (name, scheme, " | ".join(cells)))


def gauge_figure(case, series, path):
    """The depth hydrographs at the gauges: one panel per gauge, the schemes in colour, the
    DEM's resolution solid and resample 2 dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = CASES[case]["gauges"]
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    for i, ax in enumerate(axes.flat[:len(names)]):
        for (scheme, factor), g in sorted(series.items()):
            t, d, _ = g[i]
            ax.plot(t / 3600.0, d, color=COLORS[scheme], lw=1.3 if factor == 1 else 0.9,
                    ls="-" if factor == 1 else "--",
                    label="%s, r%d" % (scheme.replace("_", " "), factor))
        ax.set_title(names[i][0], fontsize=9)
        ax.set_ylabel("depth (m)")
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time (h)")
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("%s: gauge depths (solid: the DEM's resolution, dashed: resample 2)" % case,
                 fontsize=10)
    fig.tight_layout()
    save_png(fig, path, 80)
    plt.close(fig)


def save_png(fig, path, dpi):
    """Saves a figure as a PNG of at most 256 colours (maps of noisy fields stay small)."""
    import io
    from PIL import Image
    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format="png")
    Image.open(buf).convert("RGB").quantize(256).save(path, optimize=True)


def depth_diff_figure(case, depths, bed, extent, path):
    """Maps of the final depth of local inertial and of the pipes minus shallow water over a
    shaded bed; cells dry (< 1 cm) in both are left out; symmetric colour limits (the 95th
    percentile of |difference| over both maps, at least 0.1 m; larger ones saturate)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LightSource
    ref = depths["shallow_water"]
    diffs = []
    for scheme in ("local_inertial", "pipes"):
        h = depths[scheme]
        diffs.append(np.ma.masked_where((h <= WET) & (ref <= WET), h - ref))
    both = np.concatenate([np.abs(d.compressed()) for d in diffs])
    lim = max(0.1, float(np.percentile(both, 95)))
    ny, nx = ref.shape
    stacked = nx > 1.3 * ny  # a wide tile: one map above the other
    if stacked:
        fig, axes = plt.subplots(2, 1, figsize=(10, 2 * 8.6 * ny / nx + 0.8),
                                 constrained_layout=True)
    else:
        fig, axes = plt.subplots(1, 2, figsize=(14, 6.2 * ny / nx + 0.6),
                                 constrained_layout=True)
    shade = LightSource(azdeg=315, altdeg=45).hillshade(
        np.nan_to_num(bed, nan=float(np.nanmin(bed))), vert_exag=2.0)
    # a faint shade in 4 grey levels, so the PNG stays small
    shade = np.ma.masked_where(~np.isfinite(bed), 0.7 + 0.08 * np.round(3 * shade))
    for ax, d, scheme in zip(axes, diffs, ("local inertial", "pipes")):
        ax.imshow(shade, extent=extent, cmap="gray", vmin=0, vmax=1, interpolation="nearest")
        im = ax.imshow(d, extent=extent, cmap="RdBu_r", vmin=-lim, vmax=lim,
                       interpolation="nearest")
        ax.set_title("%s: %s - shallow water, final depth (m)" % (case, scheme), fontsize=9)
        ax.set_xlabel("x (km)", fontsize=7)
        ax.set_ylabel("y (km)", fontsize=7)
        ax.tick_params(labelsize=6)
    fig.colorbar(im, ax=axes, shrink=0.8, extend="both",
                 label="m (red: deeper than shallow water)")
    save_png(fig, path, 75)
    plt.close(fig)


def hydraulic_table(case, factor, backend, rows, depths):
    ref = depths.get("shallow_water")
    print("\n%s, resample factor %d, %s:" % (case, factor, backend))
    print("| scheme | wall (s) | steps | water closure (rel.) | water out (m^3) | peak outflow "
          "(m^3/s) | outflow at half its peak (s) | flooded > 0.1 m, end (km^2) | largest "
          "flooded (km^2) | max depth (m) | max speed (m/s) | RMS depth - sw (m) | 95th pct "
          "\\|depth - sw\\| (m) | sw flooded area also flooded |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scheme, r in rows.items():
        cmp = ("", "", "")
        if ref is not None:
            h = depths[scheme]
            wet = (h > WET) | (ref > WET)
            dh = np.abs(h - ref)[wet]
            both = ((h > FLOODED) & (ref > FLOODED)).sum() / max(1, (ref > FLOODED).sum())
            cmp = ("%.3f" % np.sqrt(np.mean(dh ** 2)), "%.3f" % np.percentile(dh, 95),
                   "%.3f" % both)
        print("| %s | %.0f | %s | %.1e | %.4g | %.4g | %.0f | %.2f | %.2f | %.2f | %.2f | %s | "
              "%s | %s |" % (scheme, r["wall"], r["steps"], r["closure"],
                             r.get("out", float("nan")), r.get("peak_out", float("nan")),
                             r.get("t_half", float("nan")), r["flooded_km2"],
                             r["flooded_max_km2"], r["max_depth"], r["max_speed"], *cmp))
        if r["nonfinite"]:
            print("  warning: %s has %d non-finite depths or speeds" % (scheme, r["nonfinite"]))


def erosion_table(case, rows):
    print("\n%s with erosion, resample factor 2:" % case)
    print("| scheme | wall (s) | steps | eroded (m^3) | deposited (m^3) | deepest erosion (m) | "
          "deepest deposition (m) | pits > %g m | eroded volume in pits | of it within 3 cells "
          "of an edge | flow's erosion, ledger (m^3) | flow's deposition, ledger (m^3) | "
          "material closure (rel.) |" % PIT)
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scheme, r in rows.items():
        print("| %s | %.0f | %s | %.4g | %.4g | %.4g | %.4g | %d | %.3f | %.3f | %.4g | %.4g | "
              "%.1e |" % (scheme, r["wall"], r["steps"], r["eroded"], r["deposited"],
                          r["max_erosion"], r["max_deposition"], r["pits"], r["pit_share"],
                          r["edge_pit_share"], r["gross"][0], r["gross"][1],
                          r["material_closure"]))
        if r["nonfinite"]:
            print("  warning: %s has %d non-finite erosion values" % (scheme, r["nonfinite"]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--backend", default="opencl")
    ap.add_argument("--factors", default="1,2")
    ap.add_argument("--erosion", action="store_true",
                    help="also run each scheme at resample 2 with erosion on")
    ap.add_argument("--erodem", default=ERODEM, help="the erodem binary (default: $ERODEM or "
                    "build/cli/erodem)")
    ap.add_argument("--figures", default=os.path.join(ROOT, "docs", "experiments"),
                    help="folder for the PNG figures")
    ap.add_argument("--reuse", action="store_true",
                    help="take the runs stored in out/schemes instead of running them")
    a = ap.parse_args()
    if not a.reuse and not os.path.exists(a.erodem):
        ap.error("no erodem binary at %s (--erodem or ERODEM)" % a.erodem)
    log = lambda s: print(s, flush=True)  # noqa: E731
    series = {}
    for factor in [int(x) for x in a.factors.split(",")]:
        rows, depths = {}, {}
        for scheme in SCHEMES:
            r = run(a.case, scheme, factor, a.backend, a.erodem, log, reuse=a.reuse)
            if r is None:
                print("%s failed" % scheme)
                continue
            rows[scheme], depths[scheme] = summary(*r)
            series[(scheme, factor)] = gauges(r[0])
        with h5py.File(output_path(a.case, SCHEMES[0], factor, False), "r") as f:
            backend = f.attrs["backend"]  # as run (--reuse takes stored runs)
            backend = backend.decode() if isinstance(backend, bytes) else backend
        hydraulic_table(a.case, factor, backend, rows, depths)
        if "shallow_water" in rows:
            picked = snap(a.case, series, factor)
            if picked is not None:
                print("gauges at r%d: the coarse cells taken, (row, column) of the %d x %d "
                      "around each from the north-west: %s"
                      % (factor, 2 * SNAP + 1, 2 * SNAP + 1, picked))
        if factor == 1 and len(depths) == len(SCHEMES):
            with h5py.File(output_path(a.case, "shallow_water", 1, False), "r") as f:
                bed = f["bed"][0]
                x, y = f["x"][...], f["y"][...]
            extent = [x[0] / 1e3, x[-1] / 1e3, y[-1] / 1e3, y[0] / 1e3]  # km
            depth_diff_figure(a.case, depths, bed, extent,
                              os.path.join(a.figures, "schemes_%s_depth_diff.png" % a.case))
    print("\n%s gauges:" % a.case)
    gauge_table(a.case, series)
    gauge_figure(a.case, series, os.path.join(a.figures, "schemes_%s_gauges.png" % a.case))
    if a.erosion:
        rows = {}
        for scheme in SCHEMES:
            r = run(a.case, scheme, 2, a.backend, a.erodem, log, erosion=True, reuse=a.reuse)
            if r is None:
                print("%s with erosion failed" % scheme)
                continue
            rows[scheme] = erosion_summary(*r)
        erosion_table(a.case, rows)


if __name__ == "__main__":
    main()
