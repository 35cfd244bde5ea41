#!/bin/sh
# erodem — the compiler launcher of the CPU kernel builds (kernels/CMakeLists.txt): GCC's
# -fopt-info-vec-all=FILE appends to FILE, so a recompiled source would add its report to the
# last one's (tests/cpu_vectorisation.py would count every loop twice). Removes FILE (and makes
# its folder, which GCC does not), then runs the compile command it was given.
for arg in "$@"; do
  case $arg in
  -fopt-info-vec-all=*)
    report=${arg#-fopt-info-vec-all=}
    mkdir -p "$(dirname "$report")"
    rm -f "$report"
    ;;
  esac
done
exec "$@"
