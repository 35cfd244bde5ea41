"""Sediment capacity x rain intensity on Big Tujunga: one command runs the sweep and draws
eroded volume against both parameters.

    python3 experiments/sweeps/run_sweep.py [--workers 2] [--quick]

Runs erodem.sweep over config.toml (beside this file) with erosion.sediment_capacity in
CAPACITIES and rain.rate in RAIN_RATES, in worker processes, and writes under
out/sweeps/ (relative to the repository root; git-ignored):
- member_NNN.h5: one result file per member,
- sweep.csv: the table erodem.sweep returns (parameters, metrics, paths, errors),
- eroded_volume.png: eroded volume against sediment capacity, one line per rain rate, and
  against rain rate, one line per capacity.
Uses an installed erodem, else the build tree's (ERODEM_BUILD_DIR, default build).
"""

import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))

CAPACITIES = [0.0025, 0.005, 0.01, 0.02]  # erosion.sediment_capacity K_c (s)
RAIN_RATES = ["10 mm/h", "20 mm/h", "40 mm/h"]  # rain.rate
KC = "erosion.sediment_capacity [s]"  # the sweep table's column: SI numbers, unit in the name


def import_erodem():
    build = os.path.join(REPO, os.environ.get("ERODEM_BUILD_DIR", "build"), "python")
    if os.path.isdir(os.path.join(build, "erodem")):
        sys.path.insert(0, build)
        os.environ["PYTHONPATH"] = os.pathsep.join(
            [build] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
        )
    import erodem

    return erodem


def plot(table, path):
    """Eroded volume (m^3) against sediment capacity and against rain rate."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FormatStrFormatter, NullFormatter

    ok = table[table["error"] == ""].copy()
    ok["rain_mm_h"] = ok["rain.rate [m/s]"] * 3.6e6  # m/s -> mm/h
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for rain, g in ok.groupby("rain_mm_h"):
        g = g.sort_values(KC)
        a.plot(g[KC], g["eroded_volume [m^3]"], "o-", label="%g mm/h" % round(rain, 6))
    a.set_xscale("log")
    a.set_yscale("log")
    a.set_xlabel("sediment capacity K_c (s)")
    a.set_ylabel("eroded volume (m$^3$)")
    a.set_title("eroded volume vs sediment capacity")
    a.legend(title="rain rate")
    a.grid(True, which="both", alpha=0.3)
    for kc, g in ok.groupby(KC):
        g = g.sort_values("rain_mm_h")
        b.plot(g["rain_mm_h"], g["eroded_volume [m^3]"], "s-", label="K_c = %g s" % kc)
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("rain rate (mm/h)")
    b.set_ylabel("eroded volume (m$^3$)")
    b.set_title("eroded volume vs rain intensity")
    b.legend()
    b.grid(True, which="both", alpha=0.3)
    for ax in (a, b):
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(NullFormatter())
    a.set_xticks(sorted(ok[KC].unique()))
    b.set_xticks(sorted(ok["rain_mm_h"].round(6).unique()))
    minutes = ok["time [s]"].max() / 60.0
    fig.suptitle("Big Tujunga, 256 x 256 cells of 30 m, %g min of rain (erodem.sweep, %d members)"
                 % (minutes, len(table)))
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, path)  # never a half-written figure


def main():
    ap = argparse.ArgumentParser(description="Sediment capacity x rain intensity sweep")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--out", default=os.path.join(REPO, "out", "sweeps"))
    ap.add_argument("--quick", action="store_true", help="a 5-minute storm (smoke test)")
    args = ap.parse_args()
    erodem = import_erodem()
    import pandas as pd

    config = os.path.join(HERE, "config.toml")
    dem_path = os.path.join(REPO, "..", "shared", "data", "dem", "big_tujunga",
                            "srtm_bigtujunga30m_utm11.tif")
    dem = erodem.read_dem(dem_path, window=[600, 200, 256, 256])
    print(dem, "elevation %.0f .. %.0f m" % (dem.elevation.min(), dem.elevation.max()))
    os.makedirs(args.out, exist_ok=True)
    t0 = time.perf_counter()
    table = erodem.sweep(
        dem,
        grid={"erosion.sediment_capacity": CAPACITIES, "rain.rate": RAIN_RATES},
        config=config,
        duration="5 min" if args.quick else None,
        backend="cpu",
        workers=args.workers,
        output_dir=args.out,
        overwrite=True,
    )
    wall = time.perf_counter() - t0
    csv = os.path.join(args.out, "sweep.csv")  # written by erodem.sweep
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(table.drop(columns=["output"]).to_string())
    failed = table[table["error"] != ""]
    print("%d members in %.1f s wall with %d workers; %d failed" % (len(table), wall, args.workers,
                                                                    len(failed)))
    png = os.path.join(args.out, "eroded_volume.png")
    plot(table, png)
    print("wrote %s, %s and %d result files" % (csv, png, len(table) - len(failed)))
    return 1 if len(failed) else 0


if __name__ == "__main__":
    sys.exit(main())
