#!/usr/bin/env python3
"""erodem — fuzzing the command line with mutated configs and rasters (issue 19).

Each case writes a small valid run (a 12 x 10 ASCII grid DEM and a config with most processes
on), mutates the config or the raster, and runs `erodem run` on it. Every case must end with a
documented exit code (docs/cli.md: 0, 2, 65, 66, 73, 74, 75, 78), never a signal, an internal
error (70) or a hang (the time limit), and a failing case must say exactly one `erodem:` line
on stderr. The cases are drawn from a seeded generator, so a failure is reproduced by its seed
and case number.

Usage:  python3 tests/fuzz_cli.py ERODEM [--cases N] [--seed S] [--timeout SECONDS]
ctest runs a small budget (CliFuzz); run more by hand, e.g. --cases 2000.
"""

from __future__ import annotations

import argparse
import collections
import os
import random
import subprocess
import sys
import tempfile
from pathlib import Path

DOCUMENTED = {0, 2, 65, 66, 73, 74, 75, 78}

CONFIG = """[dem]
path = "dem.asc"
crs = "EPSG:32610"
[initial]
water_depth = 0.01
[time]
steps = 6
dt = 0.5
[flow]
scheme = "local_inertial"
manning_n = 0.035
[rain]
rate = "50 mm/h"
[erosion]
law = "mei"
enabled = true
[thermal]
enabled = true
talus_angle = 35.0
[snow]
enabled = true
initial = "1 cm"
[infiltration]
enabled = true
ksat = "5 mm/h"
[terrain_classes]
enabled = true
interval = 2
rock.manning_n = 0.03
[boundary]
east = "open"
[output]
path = "out.h5"
every = 3
"""

VALUES = ["-1", "0", "1e300", "-1e300", "1e-300", '"nan"', '"inf"', '""', '"abc"',
          '"10 furlongs"', "[1, 2]", "true", "{ a = 1 }", '"0,5"', '"1e39 m"', "nan", "inf",
          '"/nonexistent/x.tif"', "2147483648", "-0.0", '"0 s"', "[[0, 1], [0, 2]]",
          '"dem.asc"', "3.5"]


def dem_text(nx: int = 12, ny: int = 10) -> str:
    rows = []
    for r in range(ny):
        rows.append(" ".join(f"{100 + 3 * c + 2 * r + ((c * r) % 5):.1f}" for c in range(nx)))
    return (f"ncols {nx}\nnrows {ny}\nxllcorner 500000\nyllcorner 4000000\ncellsize 10\n"
            "NODATA_value -9999\n" + "\n".join(rows) + "\n")


def mutate_config(rng: random.Random, text: str) -> tuple[str, str]:
    lines = text.splitlines()
    keyed = [i for i, l in enumerate(lines) if "=" in l]
    kind = rng.choice(["value", "value", "value", "delete", "unknown", "truncate", "header"])
    if kind == "value":
        i = rng.choice(keyed)
        key = lines[i].split("=")[0].strip()
        # a count of steps is not made huge: 2^31 steps is a valid run, only a long one
        v = rng.choice([x for x in VALUES if not (key in ("steps", "every", "interval") and
                                                 x == "2147483648")])
        lines[i] = f"{key} = {v}"
        return "\n".join(lines) + "\n", f"config {key} = {v}"
    if kind == "delete":
        i = rng.randrange(len(lines))
        return "\n".join(lines[:i] + lines[i + 1:]) + "\n", f"config line {i + 1} deleted"
    if kind == "unknown":
        i = rng.choice(keyed)
        lines.insert(i + 1, "frobnicate = 1")
        return "\n".join(lines) + "\n", f"config unknown key after line {i + 1}"
    if kind == "truncate":
        k = rng.randrange(len(text))
        return text[:k], f"config truncated at byte {k}"
    headers = [i for i, l in enumerate(lines) if l.startswith("[")]
    i = rng.choice(headers)
    lines.append(lines[i])
    return "\n".join(lines) + "\n", f"config table {lines[i]} twice"


def mutate_dem(rng: random.Random, text: str) -> tuple[str, str]:
    lines = text.splitlines()
    kind = rng.choice(["cell", "cell", "header", "truncate", "garbage", "rows"])
    if kind == "cell":
        r = rng.randrange(6, len(lines))
        cells = lines[r].split()
        c = rng.randrange(len(cells))
        v = rng.choice(["nan", "-1e39", "1e39", "abc", "-9999", "1e30", "-20000", "inf", ""])
        cells[c] = v
        lines[r] = " ".join(cells)
        return "\n".join(lines) + "\n", f"dem cell ({c}, {r - 6}) = {v!r}"
    if kind == "header":
        i = rng.randrange(6)
        key = lines[i].split()[0]
        v = rng.choice(["0", "-5", "1000000", "abc", "1e308", "13"])
        lines[i] = f"{key} {v}"
        return "\n".join(lines) + "\n", f"dem {key} {v}"
    if kind == "truncate":
        k = rng.randrange(len(text))
        return text[:k], f"dem truncated at byte {k}"
    if kind == "rows":
        return "\n".join(lines[:-3]) + "\n", "dem 3 rows short"
    raw = bytearray(text.encode())
    for _ in range(rng.randrange(1, 40)):
        raw[rng.randrange(len(raw))] = rng.randrange(256)
    return raw.decode("latin-1"), "dem random bytes"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("erodem")
    ap.add_argument("--cases", type=int, default=60)
    ap.add_argument("--seed", type=int, default=19)
    ap.add_argument("--timeout", type=float, default=60.0)
    args = ap.parse_args()
    args.erodem = os.path.abspath(args.erodem)
    rng = random.Random(args.seed)
    codes: collections.Counter[int] = collections.Counter()
    failures = []
    with tempfile.TemporaryDirectory(prefix="erodem_fuzz_") as tmp:
        for case in range(args.cases):
            d = Path(tmp) / f"case{case}"
            d.mkdir()
            config, dem = CONFIG, dem_text()
            what = []
            if rng.random() < 0.6:
                config, w = mutate_config(rng, config)
                what.append(w)
            if not what or rng.random() < 0.4:
                dem, w = mutate_dem(rng, dem)
                what.append(w)
            (d / "c.toml").write_text(config, encoding="latin-1")
            (d / "dem.asc").write_text(dem, encoding="latin-1")
            env = dict(os.environ, OMP_NUM_THREADS="1")
            try:
                p = subprocess.run([args.erodem, "run", "c.toml", "--backend", "cpu"], cwd=d,
                                   capture_output=True, text=True, errors="replace",
                                   timeout=args.timeout, env=env)
            except subprocess.TimeoutExpired:
                failures.append((case, "; ".join(what), f"no exit within {args.timeout} s", ""))
                codes["timeout"] += 1
                continue
            code = p.returncode
            codes[code] += 1
            said = [l for l in p.stderr.splitlines() if l.startswith("erodem:")]
            problem = ""
            if code < 0:
                problem = f"killed by signal {-code}"
            elif code not in DOCUMENTED:
                problem = f"exit {code}, not a documented code"
            elif code != 0 and len(said) != 1:
                problem = f"exit {code} with {len(said)} 'erodem:' lines"
            if problem:
                failures.append((case, "; ".join(what), problem, p.stderr[-600:]))
    print(f"fuzz_cli: {args.cases} cases (seed {args.seed}); exit codes: " +
          ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=lambda kv: str(kv[0]))))
    for case, what, problem, err in failures:
        print(f"FAIL case {case} ({what}): {problem}\n{err}")
    print(f"fuzz_cli: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
