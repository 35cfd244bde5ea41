#!/usr/bin/env python3
"""erodem — the datasets of groups of two result files, row by row (tests/mpi.sh).

Usage: h5_rows.py REFERENCE RESULT GROUP... [--ledger] [--continued]

For each GROUP (one process for all: Python and h5py take most of a second to start), every
dataset under GROUP in REFERENCE must be in RESULT, with its shape, and the other way
round. With --continued (RESULT is a run continued from a restart file, which writes only the
steps and snapshots from there on) a dataset of RESULT may hold fewer rows along the first
(unlimited) dimension, the other dimensions equal: its rows are compared with REFERENCE's last
rows, and the step and time datasets among them show that those are the same steps. h5diff
does not compare such datasets at all: it calls them "not comparable" and exits 0.

The sections' cumulative volumes (sections/volume, sections/sediment_volume) count from the
restart on (docs/results.md): there RESULT's rows are compared with REFERENCE's last rows less
the row before them, within a relative 1e-12 of the largest magnitude among the reference's
rows compared and the one before (the two sums add the same steps' volumes in a different
order). The per-step discharges beside them are compared exactly.

Otherwise the values must be equal: NaN to NaN, an infinity to the same infinity. With --ledger
(OpenCL, where each MPI rank sums its own rows' tallies on the device and the ranks' sums are
added in rank order), in the groups /diagnostics and /restart only: the ledger's
tallies and volumes (ledger_*, *_volume) within a relative 1e-12 (0 where the reference is 0),
the relative closure errors within 1e-12, the other closure errors within 1e-9 m^3; a tally
that missed or doubled a band's halo rows is off by a few per cent.

Prints a line per dataset that differs, with its largest difference, and a summary line per
group; exits 1 on any difference, 2 on a file or group that cannot be read.
"""
import fnmatch
import sys

import h5py
import numpy as np


# The groups that hold the ledger (--ledger applies there only: /sections' volumes stay exact).
LEDGER_GROUPS = {"diagnostics", "restart"}

# The cumulative datasets that count from a restart on (docs/results.md, "Sections").
RESTARTED_SUMS = {"sections/volume", "sections/sediment_volume"}


def tolerance(name, ledger):
    """(kind, bound) of dataset `name`: ('exact', 0), ('rel', r) or ('abs', a)."""
    if not ledger:
        return "exact", 0.0
    if fnmatch.fnmatch(name, "relative_*closure_error"):
        return "abs", 1e-12
    if fnmatch.fnmatch(name, "*closure_error"):
        return "abs", 1e-9
    if fnmatch.fnmatch(name, "ledger_*") or fnmatch.fnmatch(name, "*_volume"):
        return "rel", 1e-12
    return "exact", 0.0


def datasets(group):
    """{path below group: dataset} of every dataset under `group`."""
    found = {}
    group.visititems(lambda path, obj: found.__setitem__(path, obj)
                     if isinstance(obj, h5py.Dataset) else None)
    return found


def differs(a, b, kind, bound):
    """The largest difference of a from b where it is beyond the bound, else None. Equal
    values (the same infinities included) and NaN against NaN differ by 0; a finite value
    against a non-finite one by infinity; a relative bound applies to finite references."""
    if a.dtype.names or a.dtype.kind not in "fiub":
        return None if np.array_equal(a, b) else "values differ"
    a = a.astype(np.float64)
    b = b.astype(np.float64)
    with np.errstate(invalid="ignore"):
        same = (a == b) | (np.isnan(a) & np.isnan(b))
        diff = np.where(same, 0.0, np.abs(a - b))
    diff = np.where(np.isnan(diff), np.inf, diff)
    if kind == "exact":
        limit = np.zeros_like(a)
    elif kind == "rel":
        limit = np.where(np.isfinite(a), bound * np.abs(a), 0.0)
    else:
        limit = np.full_like(a, bound)
    if np.all(diff <= limit):
        return None
    return f"largest difference {np.max(diff):.3e} ({kind} bound {bound:g})"


def compare_group(ref_file, out_file, group, ledger, continued):
    """The datasets under `group` of the two open files, compared as above: the number that
    differ (a line printed for each, and a summary line), or None where the group cannot be
    read."""
    try:
        ref, out = datasets(ref_file[group]), datasets(out_file[group])
    except (OSError, KeyError) as e:
        print(f"h5_rows: {group} of {ref_file.filename} or {out_file.filename}: {e}",
              file=sys.stderr)
        return None
    bad, tails = 0, 0
    for name in sorted(set(ref) | set(out)):
        if name not in ref or name not in out:
            print(f"{group}/{name}: only in {ref_file.filename if name in ref else out_file.filename}")
            bad += 1
            continue
        a, b = ref[name][()], out[name][()]
        kind, bound = tolerance(name.split("/")[-1], ledger)
        if a.shape != b.shape:
            if continued and a.ndim >= 1 and a.shape[1:] == b.shape[1:] and \
                    b.shape[0] < a.shape[0]:
                first = a.shape[0] - b.shape[0]
                if f"{group.strip('/')}/{name}" in RESTARTED_SUMS:
                    scale = np.abs(a[first - 1:].astype(np.float64))
                    scale = float(np.max(scale[np.isfinite(scale)], initial=0.0))
                    a = a[first:] - a[first - 1]
                    kind, bound = "abs", 1e-12 * scale
                else:
                    a = a[first:]
                tails += 1
            else:
                print(f"{group}/{name}: shape {b.shape} against {a.shape}")
                bad += 1
                continue
        why = differs(a, b, kind, bound)
        if why:
            print(f"{group}/{name}: {why}")
            bad += 1
    print(f"{group}: {len(ref)} datasets, {tails} of them by the reference's last rows, "
          f"{bad} differ")
    return bad


def main(argv):
    groups = [a for a in argv[3:] if not a.startswith("--")]
    options = set(a for a in argv[3:] if a.startswith("--"))
    if len(argv) < 4 or not groups or not options <= {"--ledger", "--continued"}:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    ref_path, out_path = argv[1], argv[2]
    try:
        ref_file, out_file = h5py.File(ref_path, "r"), h5py.File(out_path, "r")
    except OSError as e:
        print(f"h5_rows: {ref_path} or {out_path}: {e}", file=sys.stderr)
        return 2
    bad = 0
    for group in groups:
        ledger = "--ledger" in options and group.strip("/") in LEDGER_GROUPS
        found = compare_group(ref_file, out_file, group, ledger, "--continued" in options)
        if found is None:
            return 2
        bad += found
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
