#!/usr/bin/env python3
"""erodem — every cell loop of the CPU reference vectorises (ctest CpuVectorisation).

The cell loops of kernels/cpu/*.cpp are the loops marked ERODEM_IVDEP or `#pragma omp simd`
(the statistics' reductions, stats_row). A loop the compiler
leaves scalar runs several times slower and no result shows it: on 2026-11-28 the water
update's loop had been scalar for a day (a conditional load GCC could not if-convert: 15.4 ms
against 4.2 ms at 1024², docs/performance.md "The water update's loop vectorises again").

This reads GCC's vectoriser report (-fopt-info-vec-all) of each CPU source of every
instruction-set build (erodem_cpu_v2, _v3, _v4: SSE4.2, AVX2, AVX-512, of which
cpu/dispatch.cpp runs the best the CPU has): the Release build writes it beside its objects
(kernels/vec/, kernels/CMakeLists.txt); without it, the source is compiled again with its own
command from compile_commands.json and the report option. It fails for every marked loop the
report calls "couldn't vectorize loop" in any of its instantiations, or never "loop
vectorized". Printed: each loop and what
the report says. Known exceptions (below) are reported, not failed. (Until 2026-11-28 07:30 the
x86-64-v2 build left thermal collapse's two loops scalar: the class talus slope's load was
conditional, and SSE4.2 has no masked loads.)

Exit 77 (skipped) for a build without compile_commands.json, not optimised (-O2/-O3: the
Release build), with sanitizers (their instrumentation changes what vectorises) or with
another compiler than GCC.
Usage: cpu_vectorisation.py BUILD_DIR
"""
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

# (file, the loop's first line): how many of its instantiations may stay scalar in each
# instruction-set build, and why. The generic sweep's loop is one template for every generic
# cell function; infiltration's and the terrain classes' cell functions hold control flow GCC
# does not if-convert (they run only with those processes on): 2 functions, in float and
# double. On v2 (SSE4.2, no masked loads) the snow pack's sliding and the shallow-water
# velocities stay scalar too: 8 reports (2026-11-28). Any further scalar instantiation (the
# snow pack's, evaporation's, ...) fails.
KNOWN_SCALAR = {
    ("sweeps.cpp", "for (int x = 1; x < W - 1; ++x)"):
    ({"v2": 8, "v3": 4, "v4": 4},
     "the generic loop: infiltration_sweep_cell and terrain_class_sweep_cell stay scalar"),
}


def marked_loops(path):
    """Line numbers (1-based) and text of the loops right after an ERODEM_IVDEP or an
    `#pragma omp simd` line (GCC reports an `omp simd` loop at its pragma's line: that line
    number then)."""
    lines = open(path, encoding="utf-8").read().split("\n")
    out = []
    for k, line in enumerate(lines[:-1]):
        simd = line.strip().startswith("#pragma omp simd")
        if (simd or line.strip() == "ERODEM_IVDEP") and lines[k + 1].lstrip().startswith("for"):
            out.append((k + 1 if simd else k + 2, lines[k + 1].strip()))
    return out


def report(entry, tmp):
    """GCC's vectoriser report for one compile_commands entry, as a list of lines: the one the
    build wrote (its command names it: kernels/CMakeLists.txt), or, where the command names none
    or the file is missing (a build by ccache, say), a compile of the source again."""
    args = shlex.split(entry["command"])
    built = [a.split("=", 1)[1] for a in args if a.startswith("-fopt-info-vec-all=")]
    if built:
        path = built[0]
        if not os.path.isabs(path):
            path = os.path.join(entry["directory"], path)
        if os.path.exists(path):
            return open(path, encoding="utf-8").read().split("\n"), True
        args = [a for a in args if not a.startswith("-fopt-info-vec-all=")]
    # one report per source and instruction-set build (they compile in parallel)
    level = re.search(r"erodem_cpu_(v[234])\.dir", entry["command"]).group(1)
    out = os.path.join(tmp, f"{os.path.basename(entry['file'])}.{level}.vec")
    # drop the object and dependency outputs; compile to nothing
    cleaned, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a in ("-o", "-MF", "-MT"):
            skip = True
            continue
        if a == "-MD":
            continue
        cleaned.append(a)
    cleaned += ["-o", os.devnull, "-fopt-info-vec-all=" + out]
    subprocess.run(cleaned, cwd=entry["directory"], check=True)
    return open(out, encoding="utf-8").read().split("\n"), False


def main():
    build = sys.argv[1]
    db_path = os.path.join(build, "compile_commands.json")
    if not os.path.exists(db_path):
        print(f"{db_path} not found (CMAKE_EXPORT_COMPILE_COMMANDS): skipped")
        return 77
    db = json.load(open(db_path, encoding="utf-8"))
    isa = re.compile(r"erodem_cpu_(v[234])\.dir")
    entries = [e for e in db
               if "/kernels/cpu/" in e["file"] and isa.search(e["command"])
               and e["file"].endswith(".cpp")]
    if not entries:
        print("no erodem_cpu_v* sources in compile_commands.json (not x86-64): skipped")
        return 77
    if any("-fsanitize" in e["command"] for e in entries):
        print("a sanitizer build (its instrumentation changes what vectorises): skipped")
        return 77
    if not all(re.search(r"(^|\s)-O[23](\s|$)", e["command"]) for e in entries):
        print("not an optimised build (-O2/-O3: CMAKE_BUILD_TYPE=Release): skipped")
        return 77
    compiler = shlex.split(entries[0]["command"])[0]
    version = subprocess.run([compiler, "--version"], capture_output=True, text=True).stdout
    if "clang" in version.lower() or not ("GCC" in version or "g++" in version or "c++" in compiler):
        print(f"{compiler} is not GCC (the report's wording is GCC's): skipped")
        return 77
    failed = checked = 0
    with tempfile.TemporaryDirectory() as tmp:
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
            reports = list(pool.map(lambda e: report(e, tmp), entries))
        from_build = sum(built for _, built in reports)
        print(f"vectoriser reports: {from_build} of {len(reports)} written by the build, "
              f"{len(reports) - from_build} compiled here")
        for entry, (rep, _) in zip(entries, reports):
            name = os.path.basename(entry["file"])
            level = isa.search(entry["command"]).group(1)
            for line_no, text in marked_loops(entry["file"]):
                at = re.compile(re.escape(f"{name}:{line_no}:") + r"\d+: ")
                here = [r for r in rep if at.search(r)]
                vectorised = sum("optimized: loop vectorized" in r for r in here)
                scalar = sum("missed: couldn't vectorize loop" in r for r in here)
                checked += 1
                allowances, why = KNOWN_SCALAR.get((name, text), ({}, ""))
                allowed = allowances.get(level, 0)
                verdict = ("FAIL" if not vectorised or scalar > allowed else
                           "known" if scalar else "ok")
                print(f"{level} {name}:{line_no}: {vectorised} instantiation(s) vectorised, {scalar} left "
                      f"scalar (allowed {allowed}): {verdict}" +
                      (f" ({why})" if verdict == "known" else ""))
                if verdict == "FAIL":
                    failed += 1
                    for r in here:
                        if "missed: not vectorized" in r:
                            print("    " + r.split(": ", 1)[-1])
    print(f"cpu vectorisation: {checked} cell loops (every instruction-set build), {failed} left "
          f"scalar (bound 0)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
