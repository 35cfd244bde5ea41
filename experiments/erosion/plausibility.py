#!/usr/bin/env python3
"""Plausibility of the physical erosion law (issue 17): sediment yields of two storms with the
physical default (erosion.law = "physical") and with Mei et al. (2007)'s law, at the DEM's
resolution and coarsened twice (dem.resample = 2), beside published yields of comparable
catchments; and float32 against float64 with the physical default.

Cases (docs/experiments/erosion.md records a run):
  - tujunga: 1 h of 50 mm/h over the whole Big Tujunga tile (SRTM 30 m, 1197 x 643 cells),
    open edges, everything else default (local inertial flow, CFL-adaptive step, thermal off),
    experiments/erosion/tujunga.toml. The law is physical or mei with its default constants
    (the issue's "tried as a new user would").
  - puget: the Puget Sound main job, experiments/puget_sound/config.toml as it is (Mei's law with
    its tuned constants, slope collapse on, fixed-level edges, the sea at 0 m), and the same with
    erosion.law = physical (the Mei constants are then unused).
Every run is the CPU reference with one thread (numerics.threads = 1), float32 unless said.
The runs of the first study have no infiltration (infiltration.enabled = false: all the rain
runs off, as before issue 18); the *_inf runs repeat the physical law's with Green-Ampt
infiltration into a loam 1 m deep (Rawls et al. 1983's K_sat 0.34 cm/h, psi 8.89 cm, delta
theta 0.3: the main job's soil).

Yields: the ledger's "sediment out" (what left through the edges and into the sea). The
physical law books solid volumes (m^3 of grains): tonnes = m^3 * rho_s, rho_s = 2650 kg/m^3.
Mei's law has no porosity: its volumes are bed volumes; they are converted as a bed of porosity
0.4 (the physical default soil), tonnes = m^3 * 2650 * (1 - 0.4) / 1000. Per km^2: over the
active (land) cells of the grid.

Precision: the tujunga storm at 30 m, float64 against float32 (the float32 run is the one of
the yield table), with the physical law and, as a yardstick, with Mei's: relative L2
difference of the final erosion field (bed change), also from `erodem compare`, and the
differences of the eroded and deposited volumes (final erosion field, as
experiments/precision/compare.py computes them, and the ledger's gross ones) and of the
sediment out.

Usage (from the repository root, after `bash scripts/setup.sh`, or with a binary built
elsewhere through --erodem or the ERODEM environment variable):
  python3 experiments/erosion/plausibility.py [--erodem PATH] [--reuse] [--only NAME,...]
      [--figures docs/experiments]
Results go to out/erosion/<run>.h5 and .log (replaced); --reuse reads those instead of running
again. The numbers go to <figures>/erosion_plausibility.json, the figure to
<figures>/erosion_yields.png.
"""
import argparse
import json
import os
import re
import subprocess
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ERODEM = os.environ.get("ERODEM", os.path.join(ROOT, "build", "cli", "erodem"))

RHO_S = 2650.0  # kg/m^3, the grain density (erosion.sediment_density's default)
PHI = 0.4  # the soil's porosity (erosion.soil.porosity's default), for Mei's bed volumes

COMMON = ["numerics.threads=1", "output.restart_state=false"]
CASES = {
    "tujunga": {
        "config": "experiments/erosion/tujunga.toml",
        "sets": ["time.adaptive=true"],  # the default is a fixed 0.05 s step
        "title": "Big Tujunga, 1 h of 50 mm/h, open edges",
    },
    "puget": {
        "config": "experiments/puget_sound/config.toml",
        "sets": [],
        "title": "Puget Sound main job (45 mm over 2 h, peak 30 mm/h, 3 h)",
    },
}
# (name, case, resample factor, law, precision[, infiltration])
RUNS = [
    ("tujunga_physical_r1", "tujunga", 1, "physical", "float32"),
    ("tujunga_mei_r1", "tujunga", 1, "mei", "float32"),
    ("tujunga_physical_r2", "tujunga", 2, "physical", "float32"),
    ("tujunga_mei_r2", "tujunga", 2, "mei", "float32"),
    ("puget_physical_r1", "puget", 1, "physical", "float32"),
    ("puget_mei_r1", "puget", 1, "mei", "float32"),
    ("puget_physical_r2", "puget", 2, "physical", "float32"),
    ("puget_mei_r2", "puget", 2, "mei", "float32"),
    ("tujunga_physical_r1_f64", "tujunga", 1, "physical", "float64"),
    ("tujunga_mei_r1_f64", "tujunga", 1, "mei", "float64"),
    ("tujunga_physical_r1_inf", "tujunga", 1, "physical", "float32", True),
    ("tujunga_physical_r2_inf", "tujunga", 2, "physical", "float32", True),
    ("puget_physical_r1_inf", "puget", 1, "physical", "float32", True),
    ("puget_physical_r2_inf", "puget", 2, "physical", "float32", True),
]
# the soil of the *_inf runs (the main job's)
SOIL = ["infiltration.moisture_deficit=0.3", "infiltration.soil_depth=1.0"]
# (float64 reference, float32 run): the physical default, and Mei's law as the yardstick of the
# validation issue's check
PRECISION_PAIRS = [("tujunga_physical_r1_f64", "tujunga_physical_r1"),
                   ("tujunga_mei_r1_f64", "tujunga_mei_r1")]

# Published yields for comparison (docs/experiments/erosion.md gives the sources), as bands in
# t/km^2 per YEAR (annual means, not single events).
# San Gabriel Mountains (Lave & Burbank 2004, JGR 109, F01006): twentieth-century landscape
# erosion rates from debris-basin and reservoir infilling, 1.6 and 0.9 mm/yr on average;
# as tonnes at 1590 kg/m^3 (a bed of porosity 0.4) to 2650 kg/m^3 (rock): 1 mm/yr over a km^2
# is 1e3 m^3/yr, so mm/yr times kg/m^3 is t/km^2/yr.
SAN_GABRIEL = (0.9 * RHO_S * (1 - PHI), 1.6 * RHO_S)  # t/km^2/yr
# Puget Sound (Czuba et al. 2011, USGS Fact Sheet 2011-3083): 6.5 million tons a year from the
# rivers into Puget Sound and its adjacent waters, over a catchment of 31,440-42,800 km^2.
PUGET = (6.5e6 / 42800.0, 6.5e6 / 31440.0)
BANDS = {"tujunga": ("San Gabriel Mts., annual (Lavé & Burbank 2004)", SAN_GABRIEL),
         "puget": ("Puget Sound rivers, annual (Czuba et al. 2011)", PUGET)}


def command(name, erodem):
    _, case, factor, law, precision, *rest = next(r for r in RUNS if r[0] == name)
    infiltration = bool(rest and rest[0])
    c = CASES[case]
    out = os.path.join(ROOT, "out", "erosion", name + ".h5")
    sets = c["sets"] + COMMON + ["erosion.law=%s" % law, "numerics.precision=%s" % precision]
    sets += ["infiltration.enabled=%s" % ("true" if infiltration else "false")]
    if infiltration:
        sets += SOIL
    if factor > 1:
        sets.append("dem.resample=%d" % factor)
    cmd = [erodem, "run", c["config"], "--backend", "cpu", "--output", out, "--overwrite"]
    for s in sets:
        cmd += ["--set", s]
    return cmd, out


def run(name, erodem, reuse, log):
    cmd, out = command(name, erodem)
    logfile = out[:-3] + ".log"
    if reuse and os.path.exists(out) and os.path.exists(logfile):
        return out, logfile
    os.makedirs(os.path.dirname(out), exist_ok=True)
    log("$ " + " ".join(os.path.relpath(a, ROOT) if a.startswith(ROOT) else a for a in cmd))
    start = time.time()
    with open(logfile, "w") as f:
        done = subprocess.run(cmd, cwd=ROOT, stdout=f, stderr=subprocess.STDOUT)
    log("  exit %d after %.0f s" % (done.returncode, time.time() - start))
    if done.returncode != 0:
        raise SystemExit("%s failed, see %s" % (name, logfile))
    return out, logfile


NUM = r"([-+0-9.eE]+)"


def parse_log(path):
    """The ledger's volumes (m^3), the tonnes line of the physical law, steps and wall time."""
    text = open(path).read()

    def grab(pattern, cast=float):
        m = re.search(pattern, text)
        return cast(m.group(1)) if m else None

    r = {
        "rain_m3": grab(r"rain\s+" + NUM),
        "water_out_m3": grab(r"\n\s+out\s+" + NUM),
        "water_closure_rel": grab(r"closures: water \S+ m\^3 \(" + NUM),
        "sed_out_m3": grab(r"sediment out\s+" + NUM),
        "eroded_m3": grab(r"eroded\s+" + NUM + r"\s+deposited"),
        "deposited_m3": grab(r"eroded\s+\S+\s+deposited\s+" + NUM),
        "from_bedrock_m3": grab(r"from bedrock\s+" + NUM),
        "bed_bulking_m3": grab(r"bed bulking\s+" + NUM),
        "material_closure_rel": grab(r"material \S+ m\^3 \(" + NUM),
        "steps": grab(r"ran (\d+) steps", int),
        "wall_s": grab(r"steps to t = \S+ s in " + NUM + " s wall"),
        "device": grab(r"backend \w+, device ([^\n]+)", str),
    }
    m = re.search(r"sediment \(solid[^)]*\): eroded " + NUM + r" t \(" + NUM
                  + r" t from bedrock\), deposited " + NUM + r" t, out " + NUM + r" t = " + NUM
                  + r" t/km\^2 over " + NUM + r" km\^2", text)
    if m:
        r["summary_t"] = {"eroded": float(m.group(1)), "from_bedrock": float(m.group(2)),
                          "deposited": float(m.group(3)), "out": float(m.group(4)),
                          "out_per_km2": float(m.group(5)), "area_km2": float(m.group(6))}
    return r


def read_h5(path):
    """Active area (km^2), the final erosion field's eroded and deposited bed volumes (m^3),
    its deepest erosion and deposition (m), the largest speed and depth over all steps."""
    with h5py.File(path, "r") as f:
        bed = f["bed"][0]
        e = f["erosion"][-1].astype(np.float64)
        area = f["cell_area"][...].astype(np.float64)[:, None]
        d = f["diagnostics"]
        vmax = float(np.nanmax(d["max_speed"][...]))
        hmax = float(np.nanmax(d["max_depth"][...]))
        dtmin = float(np.min(d["dt"][...]))
        dx = float(np.mean(f["cell_dx"][...]))
    active = np.isfinite(bed)
    e = np.where(np.isfinite(e), e, 0.0)
    return {
        "area_km2": float((active * area).sum() / 1e6),
        "cells": int(active.sum()),
        "dx_m": dx,
        "field_eroded_bed_m3": float((np.where(e > 0, e, 0) * area).sum()),
        "field_deposited_bed_m3": float((np.where(e < 0, -e, 0) * area).sum()),
        "max_erosion_m": float(e.max()),
        "max_deposition_m": float(-e.min()),
        "max_speed_ms": vmax,
        "max_depth_m": hmax,
        "min_dt_s": dtmin,
    }


def summarise(name, path, logfile):
    _, case, factor, law, precision, *rest = next(r for r in RUNS if r[0] == name)
    r = {"case": case, "resample": factor, "law": law, "precision": precision,
         "infiltration": bool(rest and rest[0])}
    r.update(parse_log(logfile))
    r.update(read_h5(path))
    # tonnes per kg/m^3 of the ledger's volumes: solid volumes (physical), bed volumes with no
    # pores (mei) taken as a bed of porosity PHI
    density = RHO_S if law == "physical" else RHO_S * (1 - PHI)
    r["tonnes_per_m3"] = density / 1000.0
    for k in ("eroded", "deposited", "sed_out"):
        r[k + "_t"] = r[k + "_m3"] * density / 1000.0
        r[k + "_t_per_km2"] = r[k + "_t"] / r["area_km2"]
    r["mean_lowering_mm"] = 1e3 * r["field_eroded_bed_m3"] / (r["area_km2"] * 1e6)
    r["runoff_out_fraction"] = r["water_out_m3"] / r["rain_m3"]
    return r


def precision(rows, paths, erodem, a, b):
    if a not in rows or b not in rows:
        return None
    with h5py.File(paths[a], "r") as f64, h5py.File(paths[b], "r") as f32:
        e64 = f64["erosion"][-1].astype(np.float64)
        e32 = f32["erosion"][-1].astype(np.float64)
        area = f64["cell_area"][...][:, None]
    ok = np.isfinite(e64) & np.isfinite(e32)
    diff = (e32 - e64)[ok]
    rel_l2 = float(np.sqrt(np.sum(diff ** 2) / np.sum(e64[ok] ** 2)))
    w = np.broadcast_to(area, e64.shape)[ok]
    # the same norm weighted by the cell area (the rows of a UTM tile differ little)
    rel_l2_area = float(np.sqrt(np.sum(w * diff ** 2) / np.sum(w * e64[ok] ** 2)))
    cmp = subprocess.run([erodem, "compare", os.path.relpath(paths[b], ROOT),
                          os.path.relpath(paths[a], ROOT), "--json", "--fields",
                          "erosion,bed,water_depth,sediment"], cwd=ROOT, capture_output=True,
                         text=True)
    try:
        tool = json.loads(cmp.stdout)
    except ValueError:
        tool = cmp.stdout + cmp.stderr
    r64, r32 = rows[a], rows[b]

    def rel(k):
        return (r32[k] - r64[k]) / r64[k] if r64[k] else None

    return {
        "reference": a, "float32": b,
        "erosion_rel_l2": rel_l2, "erosion_rel_l2_area_weighted": rel_l2_area,
        "erosion_max_abs_diff_m": float(np.abs(diff).max()),
        "erosion_max_m_float64": float(np.abs(e64[ok]).max()),
        "erodem_compare": tool,
        "sed_out_rel_diff": rel("sed_out_m3"), "eroded_rel_diff": rel("eroded_m3"),
        "deposited_rel_diff": rel("deposited_m3"),
        "field_eroded_rel_diff": rel("field_eroded_bed_m3"),
        "field_deposited_rel_diff": rel("field_deposited_bed_m3"),
        "wall_s": {a: r64["wall_s"], b: r32["wall_s"]},
        "steps": {a: r64["steps"], b: r32["steps"]},
    }


def table(rows):
    print("| catchment | cell | law | infiltration | rain (m^3) | water out / rain | eroded (t) | deposited (t) "
          "| out (t) | out (t/km^2) | eroded (t/km^2) | mean bed lowering (mm) | deepest "
          "erosion (m) | max speed (m/s) | steps | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        if r["precision"] != "float32":
            continue
        print("| %s | %.0f m | %s | %s | %.3e | %.2f | %.3e | %.3e | %.3e | %.4g | %.4g | %.3g | %.3g "
              "| %.3g | %d | %.0f |"
              % (r["case"], r["dx_m"], r["law"], "loam" if r["infiltration"] else "none",
                 r["rain_m3"], r["runoff_out_fraction"],
                 r["eroded_t"], r["deposited_t"], r["sed_out_t"], r["sed_out_t_per_km2"],
                 r["eroded_t_per_km2"], r["mean_lowering_mm"], r["max_erosion_m"],
                 r["max_speed_ms"], r["steps"], r["wall_s"]))


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.4), sharey=True)
    colors = {"physical": "tab:blue", "mei": "tab:red"}
    for ax, case in zip(axes, ("tujunga", "puget")):
        runs = [r for r in rows.values() if r["case"] == case and r["precision"] == "float32"]
        runs.sort(key=lambda r: (r["law"] != "physical", r["infiltration"], r["resample"]))
        label, (lo, hi) = BANDS[case]
        ax.axhspan(lo, hi, color="0.8", zorder=0)
        x = np.arange(len(runs))
        out = [max(r["sed_out_t_per_km2"], 1e-3) for r in runs]
        ero = [max(r["eroded_t_per_km2"], 1e-3) for r in runs]
        ax.bar(x - 0.2, out, 0.4, color=[colors[r["law"]] for r in runs])
        ax.bar(x + 0.2, ero, 0.4, color=[colors[r["law"]] for r in runs], alpha=0.4,
               hatch="//")
        for xi, v in zip(x - 0.2, out):
            ax.text(xi, v * 1.15, "{:,.0f}".format(v), ha="center", va="bottom", fontsize=6.5)
        ax.set_xticks(x)
        ax.set_xticklabels(["%s%s\n%.0f m" % (r["law"], " + inf." if r["infiltration"] else "",
                                                r["dx_m"]) for r in runs], fontsize=8)
        ax.set_yscale("log")
        ax.set_ylim(10, 1e9)
        ax.set_title(CASES[case]["title"], fontsize=9)
        ax.grid(axis="y", alpha=0.3)
        handles = [Patch(color="0.8", label=label + ",\nper year"),
                   Patch(facecolor="0.35", label="out of the grid (the storm's yield)"),
                   Patch(facecolor="0.75", hatch="//", label="eroded, gross")]
        ax.legend(handles=handles, fontsize=7, loc="upper left")
    axes[0].set_ylabel("t/km² in the storm (one event)")
    fig.suptitle("Sediment per km² of one storm, physical law (blue) and Mei's law (red; bed "
                 "volume at 1590 kg/m³)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--erodem", default=ERODEM)
    p.add_argument("--reuse", action="store_true")
    p.add_argument("--only", default="", help="comma-separated run names (default: all)")
    p.add_argument("--figures", default=os.path.join(ROOT, "docs", "experiments"))
    a = p.parse_args()
    names = [r[0] for r in RUNS]
    if a.only:
        names = [n for n in names if n in a.only.split(",")]
    rows, paths = {}, {}
    for name in names:
        out, logfile = run(name, a.erodem, a.reuse, lambda s: print(s, flush=True))
        paths[name] = out
        rows[name] = summarise(name, out, logfile)
    table(rows)
    precs = [precision(rows, paths, a.erodem, *pair) for pair in PRECISION_PAIRS]
    for prec in [p for p in precs if p]:
        print("\nfloat32 - float64 (%s): erosion field relative L2 %.3e (area-weighted %.3e), "
              "max |diff| %.3e m of %.3e m; sediment out %+.3e, eroded %+.3e, deposited %+.3e "
              "(relative)" % (prec["reference"], prec["erosion_rel_l2"],
                              prec["erosion_rel_l2_area_weighted"],
                              prec["erosion_max_abs_diff_m"], prec["erosion_max_m_float64"],
                              prec["sed_out_rel_diff"], prec["eroded_rel_diff"],
                              prec["deposited_rel_diff"]))
    os.makedirs(a.figures, exist_ok=True)
    with open(os.path.join(a.figures, "erosion_plausibility.json"), "w") as f:
        json.dump({"runs": rows, "precision": [p for p in precs if p],
                   "bands_t_per_km2_per_year": {k: {"label": v[0], "range": v[1]}
                                                for k, v in BANDS.items()},
                   "rho_s": RHO_S, "mei_porosity_for_tonnes": PHI}, f, indent=1)
    if all(any(r["case"] == c for r in rows.values()) for c in CASES):
        figure(rows, os.path.join(a.figures, "erosion_yields.png"))


if __name__ == "__main__":
    main()
