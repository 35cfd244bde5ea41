#!/usr/bin/env python3
"""The snowmelt valley (experiments/snowmelt_valley/config.toml): the outlet's hydrograph
(the result file's sections/ group), the pack's and the soil's water (sum over the snapshots
of snow and infiltrated times the cell area), and the forcing (rain series and the air
temperature at the valley floor and at the top), as one figure.

Usage (from the repository root, after `erodem run experiments/snowmelt_valley/config.toml`):
  python3 experiments/snowmelt_valley/plot.py [RESULT.h5] [--figure docs/images/snowmelt_valley.png]
Prints the budget (m^3 and mm over the valley) and the outlet's peak.
"""
import argparse
import os

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DAY = 86400.0


def series(points, t):
    ts, vs = zip(*points)
    return np.interp(t, ts, vs)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("result", nargs="?",
                   default=os.path.join(ROOT, "out", "snowmelt_valley", "snowmelt_valley.h5"))
    p.add_argument("--figure", default=os.path.join(ROOT, "docs", "images", "snowmelt_valley.png"))
    a = p.parse_args()
    with h5py.File(a.result, "r") as f:
        t_q = f["sections/time"][...]
        q = f["sections/discharge"][:, 0]
        t_s = f["time"][...]
        area = f["cell_area"][...][:, None]
        snow = np.array([np.nansum(f["snow"][k] * area) for k in range(len(t_s))])
        soil = np.array([np.nansum(f["infiltrated"][k] * area) for k in range(len(t_s))])
        bed = f["bed"][0]
        total_area = float(np.sum(np.isfinite(bed) * area))
    # the config's forcing (kept in step with config.toml by hand: the figure shows it)
    rain = [(0, 0), (172800, 0), (176400, 4), (190800, 4), (194400, 0), (691200, 0), (694800, 8),
            (716400, 8), (720000, 0)]
    temp = [(0, -2.0), (259200, -2.0), (518400, 15.0), (864000, 15.0)]
    z_lo, z_hi = float(np.nanmin(bed)), float(np.nanmax(bed))
    k = int(np.argmax(q))
    mm = 1e3 / total_area
    print("valley %.1f km^2, bed %.0f-%.0f m" % (total_area / 1e6, z_lo, z_hi))
    print("pack %.4g m^3 (%.0f mm) at t = 0, %.4g m^3 (%.0f mm) at the end" %
          (snow[0], snow[0] * mm, snow[-1], snow[-1] * mm))
    print("soil %.4g m^3 (%.0f mm) at the end" % (soil[-1], soil[-1] * mm))
    print("outlet: peak %.3g m^3/s at day %.2f, volume %.4g m^3 (%.0f mm)" %
          (q[k], t_q[k] / DAY, np.sum(q[1:] * np.diff(t_q)), np.sum(q[1:] * np.diff(t_q)) * mm))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    ax1.plot(t_q / DAY, q, color="tab:blue")
    ax1.set_ylabel("outlet discharge (m$^3$/s)")
    ax1.set_title("Snowmelt valley: %.0f km$^2$, %.0f-%.0f m" % (total_area / 1e6, z_lo, z_hi))
    ax2.plot(t_s / DAY, snow * mm, "o-", color="tab:cyan", label="snow pack (water equivalent)")
    ax2.plot(t_s / DAY, soil * mm, "s-", color="tab:brown", label="soil store (infiltrated)")
    ax2.set_ylabel("mm over the valley")
    ax2.legend(fontsize=8)
    td = np.linspace(0, t_q[-1], 500)
    lapse = -0.0065
    ax3.plot(td / DAY, series(temp, td) + lapse * z_lo, color="tab:red", label="air, valley floor")
    ax3.plot(td / DAY, series(temp, td) + lapse * z_hi, color="tab:purple", label="air, top")
    ax3.axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax3.set_ylabel("°C")
    ax3.set_xlabel("day")
    ax3b = ax3.twinx()
    ax3b.fill_between(td / DAY, series(rain, td), color="tab:blue", alpha=0.3, label="rain")
    ax3b.set_ylabel("precipitation (mm/h)")
    ax3.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    os.makedirs(os.path.dirname(a.figure), exist_ok=True)
    fig.savefig(a.figure, dpi=110)
    print("figure:", a.figure)


if __name__ == "__main__":
    main()
