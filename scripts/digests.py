#!/usr/bin/env python3
"""erodem — golden digests of the reference outputs, for restructurings that must keep every
result bit for bit (docs/architecture.md, "Keeping results bit-identical").

Runs the reference scenarios through the built `erodem` CLI on every target (CPU float32 and
float64, OpenCL float32 where there is a device) and prints the SHA-256 of every dataset of
the result file: the field snapshots, `diagnostics/`, `gauges/` and `restart/` (provenance
attributes, which hold times and versions, are not hashed; a restart field stored once per
value is hashed as a row per stored time, so files of the older layout compare). The scenarios are the storm of
tests/scenarios.hpp `tujunga_storm` on the 256^2 Big Tujunga crop (local inertial +
conservative transport with adaptive steps; pipes + semi-Lagrangian with fixed steps) and the
two runs of tests/test_restart.cpp (a synthetic valley with rain series, erosion, thermal
collapse, evaporation, open and fixed-level edges; a hill with pipes, a point inflow
hydrograph and semi-Lagrangian transport), each with gauges; and the storm and the valley with
the shallow-water scheme.

Usage (from the repository root, after building build/cli/erodem):
  python3 scripts/digests.py --write digests.json    # record the digests before a change
  python3 scripts/digests.py --check digests.json    # after it: exit 1 on any difference
The CPU digests do not depend on the instruction set or the thread count (tests/test_cpu_isa.cpp);
the OpenCL ones belong to one device and driver (compare on the same machine).
"""
import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

TUJUNGA = """[dem]
path = "{root}/../shared/data/dem/big_tujunga/srtm_bigtujunga30m_utm11.tif"
window = [420, 180, 256, 256]
[time]
steps = 300
adaptive = {adaptive}
dt = {dt}
dt_max = {dt}
[flow]
scheme = "{flow}"
manning_n = 0.035
[rain]
rate = 2e-4
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.5
[transport]
scheme = "{transport}"
[thermal]
enabled = true
talus_angle = 35.0
[evaporation]
rate = 1e-6
[boundary]
north = "open"
south = "open"
east = "open"
west = "open"
[numerics]
wetness_time = 600.0
[output]
every = 100
fields = ["bed", "water_depth", "sediment", "velocity_x", "velocity_y", "erosion", "wetness",
          "flux_left", "flux_right", "flux_top", "flux_bottom"]
gauges = [[390000.0, 3800000.0], [393000.0, 3797000.0], [395500.0, 3796000.0]]
"""

VALLEY = """[dem]
synthetic = "valley"
size = 48
seed = 3
relief = "40 m"
cell_size = "10 m"
[initial]
water_depth = 0.05
[time]
duration = "8 min"
adaptive = true
cfl = 0.7
dt_max = "2 s"
[flow]
scheme = "local_inertial"
manning_n = 0.035
[rain]
series = [[0, "80 mm/h"], [200, "20 mm/h"]]
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.2
dissolving_rate = 0.01
deposition_rate = 0.05
[thermal]
enabled = true
talus_angle = 30.0
rate = 0.05
[evaporation]
rate = 1e-6
[boundary]
east = "open"
west = "fixed_level"
sea_level = 1.0
[output]
interval = "2 min"
fields = ["bed", "water_depth", "sediment", "velocity_x", "velocity_y", "erosion", "wetness"]
gauges = [[100.0, 240.0], [240.0, 240.0], [400.0, 100.0]]
"""

HILL = """[dem]
synthetic = "hill"
size = 40
seed = 5
relief = "20 m"
cell_size = "5 m"
[time]
steps = 150
dt = 0.1
[flow]
scheme = "pipes"
[rain]
rate = "30 mm/h"
[[inflow]]
point = [60.0, 140.0]
hydrograph = [[0, 0.0], [5, 2.0], [15, 0.5]]
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.5
dissolving_rate = 0.05
deposition_rate = 0.1
[transport]
scheme = "semi_lagrangian"
[boundary]
south = "open"
[output]
every = 50
fields = ["bed", "water_depth", "sediment", "erosion", "flux_left", "flux_top"]
gauges = [[60.0, 140.0], [100.0, 100.0]]
"""

SCENARIOS = {
    "tujunga_inertial": TUJUNGA.format(root=ROOT, adaptive="true", dt=2.0, flow="local_inertial",
                                       transport="conservative"),
    "tujunga_pipes": TUJUNGA.format(root=ROOT, adaptive="false", dt=0.5, flow="pipes",
                                    transport="semi_lagrangian"),
    "valley_inertial": VALLEY,
    "hill_pipes": HILL,
    # the shallow-water scheme (issue 16) on the same two: the storm with adaptive steps and
    # conservative transport, the valley with its open and fixed-level edges
    "tujunga_shallow_water": TUJUNGA.format(root=ROOT, adaptive="true", dt=2.0,
                                            flow="shallow_water", transport="conservative"),
    "valley_shallow_water": VALLEY.replace('scheme = "local_inertial"', 'scheme = "shallow_water"'),
    # and its second order (flow.order = 2) on the valley
    "valley_shallow_water_order2": VALLEY.replace('scheme = "local_inertial"',
                                                  'scheme = "shallow_water"\norder = 2'),
}
TARGETS = {
    "cpu_float32": ["--backend", "cpu", "--set", "numerics.precision=float32"],
    "cpu_float64": ["--backend", "cpu", "--set", "numerics.precision=float64"],
    "opencl_float32": ["--backend", "opencl", "--set", "numerics.precision=float32"],
}


def opencl_available(erodem):
    out = subprocess.run([erodem, "devices"], capture_output=True, text=True, check=False).stdout
    return re.search(r"^\s*\*?\s*\[0\]", out, re.M) is not None


def dataset_digests(path):
    """{dataset path: sha256 of its bytes (C order, stored dtype)} for every dataset. A
    restart field stored once per value (restart/NAME with restart/NAME_row, 2026-11-27) is
    hashed expanded to its row at each stored time, as files before that stored it, so the
    digests of the two layouts compare."""
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            rows = obj.parent.get(obj.name.rsplit("/", 1)[1] + "_row")
            data = obj[()] if rows is None else obj[()][rows[()]]
            if isinstance(data, bytes):
                raw = data
            else:
                arr = np.ascontiguousarray(np.asarray(data))
                raw = arr.tobytes() if arr.dtype.kind != "O" else repr(arr.tolist()).encode()
            out[name] = hashlib.sha256(raw).hexdigest()

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return out


def run_all(erodem, only_cpu):
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for scenario, text in SCENARIOS.items():
            config = os.path.join(tmp, scenario + ".toml")
            with open(config, "w") as fh:
                fh.write(text)
            for target, args in TARGETS.items():
                if target.startswith("opencl") and only_cpu:
                    continue
                out = os.path.join(tmp, f"{scenario}_{target}.h5")
                cmd = [erodem, "run", config, "--output", out, "--overwrite"] + args
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
                for name, digest in dataset_digests(out).items():
                    results[f"{scenario}/{target}/{name}"] = digest
                print(f"digests: {scenario} {target}: done", file=sys.stderr, flush=True)
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--erodem", default=os.path.join(ROOT, "build", "cli", "erodem"))
    group = ap.add_mutually_exclusive_group(required=True)
    group.add_argument("--write", metavar="FILE", help="write the digests to FILE (JSON)")
    group.add_argument("--check", metavar="FILE", help="compare with the digests in FILE")
    args = ap.parse_args()
    only_cpu = not opencl_available(args.erodem)
    if only_cpu:
        print("digests: no OpenCL device: CPU targets only", file=sys.stderr)
    now = run_all(args.erodem, only_cpu)
    if args.write:
        with open(args.write, "w") as fh:
            json.dump(now, fh, indent=1, sort_keys=True)
        print(f"digests: wrote {len(now)} digests to {args.write}")
        return 0
    with open(args.check) as fh:
        ref = json.load(fh)
    if only_cpu:
        ref = {k: v for k, v in ref.items() if "/opencl_" not in k}
    differ = sorted(k for k in ref if k in now and ref[k] != now[k])
    missing = sorted(k for k in ref if k not in now)
    added = sorted(k for k in now if k not in ref)
    for k in differ:
        print(f"DIFFERS  {k}")
    for k in missing:
        print(f"MISSING  {k}")
    for k in added:
        print(f"NEW      {k}")
    print(f"digests: {len(ref)} recorded, {len(differ)} differ, {len(missing)} missing, "
          f"{len(added)} new")
    return 1 if differ or missing else 0


if __name__ == "__main__":
    sys.exit(main())
