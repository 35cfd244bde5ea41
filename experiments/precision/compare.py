#!/usr/bin/env python3
"""float32 against float64 on the full-size scenarios of issue 14 (docs/model.md section 1,
docs/validation.md "float32 against float64"): runs a config with the CPU reference in float64,
the CPU reference in float32 and OpenCL in float32, and prints the eroded and deposited volumes
(from the final erosion field, as a user reads them, and the ledger's gross volumes) with their
differences from float64, and the material closure relative to what moved. The validation
report (experiments/validation/run.py) runs every case through `run_case` and asserts the same
bounds as tests/test_precision.cpp, whose 128^2 and 256^2 versions ctest runs.

Usage (from the repository root, after `bash scripts/setup.sh`):
  python3 experiments/precision/compare.py puget     # the Puget Sound main job (3 h)
  python3 experiments/precision/compare.py tujunga   # 1 h of 50 mm/h over all of Big Tujunga
  python3 experiments/precision/compare.py ridged    # 0-9000 m synthetic relief, 512^2 cells
Results go to out/precision/<case>_<target>.h5 (replaced).
"""
import os
import subprocess
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ERODEM = os.environ.get("ERODEM", os.path.join(ROOT, "build", "cli", "erodem"))

STORM = [
    "rain.rate=50 mm/h",
    "time.duration=1 h",
    "time.adaptive=true",
    "erosion.enabled=true",
    "erosion.law=mei",
    "thermal.enabled=true",
] + ["boundary.%s=open" % e for e in ("north", "south", "east", "west")]

CASES = {
    # the main job as it is (scripts/run_main.sh)
    "puget": ("experiments/puget_sound/config.toml", []),
    # one hour of 50 mm/h over the whole Big Tujunga tile with the erosion defaults
    "tujunga": ("experiments/precision/tujunga.toml", STORM),
    # 0-9000 m of relief: the largest float32 ulp of the three (9.8e-4 m)
    "ridged": ("experiments/precision/ridged.toml", STORM),
}
TITLES = {
    "puget": "the Puget Sound main job (1025^2 cells of 160 m, 0-4380 m)",
    "tujunga": "1 h of 50 mm/h over all of Big Tujunga (1197 x 643 cells of 30 m)",
    "ridged": "1 h of 50 mm/h over ridged 0-9000 m relief (512^2 cells of 100 m)",
}
TARGETS = [
    ("cpu_float64", ["--backend", "cpu", "--set", "numerics.precision=float64"]),
    ("cpu_float32", ["--backend", "cpu", "--set", "numerics.precision=float32"]),
    ("opencl_float32", ["--backend", "opencl"]),
]
# The bounds of tests/test_precision.cpp: the 1 % on the volumes, and 1e-5 of what
# moved on the material closure (the bed pair's rounding is a few 1e-7 of it).
VOLUME_BOUND = 0.01
CLOSURE_BOUND = 1e-5


def volumes(path):
    """Eroded and deposited volumes (m^3) of the final erosion field, the ledger's gross
    volumes, the material closure (m^3) and the closure relative to what moved."""
    with h5py.File(path, "r") as f:
        e = f["erosion"][-1].astype(np.float64)
        area = f["cell_area"][...] if "cell_area" in f else None
        d = f["diagnostics"]
        gross = (float(d["eroded_volume"][-1]), float(d["deposited_volume"][-1]))
        rel = float(d["relative_material_closure_error"][-1])
        closure = float(d["material_closure_error"][-1])
        if area is None:
            dx = abs(float(f["x"][1] - f["x"][0]))
            dy = abs(float(f["y"][1] - f["y"][0]))
            area = dx * dy
        e = np.where(np.isfinite(e), e, 0.0) * (area if np.ndim(area) == 0 else area[:, None])
    return e[e > 0].sum(), -e[e < 0].sum(), gross, closure, rel


def run_case(case, targets=None, log=print):
    """Runs `case` on every target (names of TARGETS; all by default) and returns
    {target: (eroded, deposited, (gross eroded, gross deposited), closure, relative closure,
    wall seconds)}. cpu_float64 always runs: it is the reference."""
    config, sets = CASES[case]
    os.makedirs(os.path.join(ROOT, "out", "precision"), exist_ok=True)
    rows = {}
    for name, args in TARGETS:
        if targets is not None and name != "cpu_float64" and name not in targets:
            continue
        out = os.path.join(ROOT, "out", "precision", "%s_%s.h5" % (case, name))
        cmd = [ERODEM, "run", config, "--output", out, "--overwrite"] + args
        for s in sets:
            cmd += ["--set", s]
        cmd += ["--set", "output.restart_state=false"]
        log("$ " + " ".join(cmd))
        start = time.time()
        subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        rows[name] = volumes(out) + (time.time() - start,)
    return rows


def main(case):
    rows = run_case(case, log=lambda s: print(s, flush=True))
    ref = rows["cpu_float64"]
    print("\n%s: eroded / deposited (m^3) from the final erosion field; gross from the ledger" % case)
    for name, (er, de, (ge, gd), closure, rel, wall) in rows.items():
        print(
            "  %-15s eroded %.6e (%+.3f %%)  deposited %.6e (%+.3f %%)  gross eroded %+.3f %%, "
            "deposited %+.3f %%  material closure %.3e m^3 = %.2e of moved  (%.0f s)"
            % (name, er, 100 * (er / ref[0] - 1), de, 100 * (de / ref[1] - 1),
               100 * (ge / ref[2][0] - 1), 100 * (gd / ref[2][1] - 1), closure, rel, wall))


if __name__ == "__main__":
    if len(sys.argv) != 2 or sys.argv[1] not in CASES:
        sys.exit(__doc__)
    main(sys.argv[1])
