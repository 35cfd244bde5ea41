#!/usr/bin/env bash
# erodem — installs everything a fresh Debian machine needs and builds the project.
# Safe to run twice: installed packages are skipped and the build is incremental.
# Usage: bash scripts/setup.sh [build-dir]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}

DEBIAN_PACKAGES=(
  build-essential cmake ninja-build pkg-config git clang-format
  libtomlplusplus-dev libcli11-dev libspdlog-dev libfmt-dev libeigen3-dev
  libgtest-dev googletest
  # Debian's GDAL reads and writes netCDF (gridded forcing, test_gridded_forcing.cpp)
  libgdal-dev gdal-bin libgeographiclib-dev
  libhdf5-dev hdf5-tools
  # MPI: `mpirun -np N erodem run` (ERODEM_MPI, docs/mpi.md; ctest -L mpi); parallel HDF5
  openmpi-bin libopenmpi-dev libhdf5-openmpi-dev
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  # Oclgrind: the OpenCL kernels under its memory and data-race checks (ctest Oclgrind)
  oclgrind
  # the VTK viewer (`erodem view`); VTK's CMake config also needs MPI (pulled in by
  # libvtk9-dev). xvfb-run (xvfb + xauth) and Mesa render it without a screen (tests).
  libvtk9-dev xvfb xauth libgl1-mesa-dri
  pybind11-dev
)

missing=()
for p in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
# (grep without -q: with -q it stops reading, gdalinfo dies of SIGPIPE, and pipefail reported
# a GDAL with netCDF as one without)
gdalinfo --formats | grep '^ *netCDF ' > /dev/null ||
  echo "setup: warning: this GDAL has no netCDF driver; netCDF gridded forcing and its tests fail"

# Python readers the tests open result files with (h5py, xarray with h5netcdf).
if ! python3 -c 'import numpy, h5py, xarray, h5netcdf' 2>/dev/null; then
  echo "setup: installing Python packages: numpy h5py xarray h5netcdf"
  python3 -m pip install -q numpy h5py xarray h5netcdf
fi
# The Python bindings (python/, docs/python.md): pybind11 (Debian pybind11-dev above, or pip),
# the build backend of `pip install .`, and what the package and its tests use (pyarrow: the
# sweep table as Parquet).
if ! python3 -c 'import scikit_build_core, pybind11, pandas, dask, distributed, tqdm, matplotlib, pytest, pyarrow' 2>/dev/null; then
  echo "setup: installing Python packages: scikit-build-core pybind11 pandas dask distributed tqdm matplotlib pytest pyarrow"
  python3 -m pip install -q scikit-build-core pybind11 pandas dask distributed tqdm matplotlib pytest pyarrow
fi

# mpi4py: Python scripts under mpirun, each process a member of an ensemble
# (tests/python/test_mpi.py, docs/python.md "Under mpirun"); its wheel loads the MPI above.
if command -v mpirun > /dev/null && ! python3 -c 'import mpi4py' 2>/dev/null; then
  echo "setup: installing Python packages: mpi4py"
  python3 -m pip install -q mpi4py
fi

# PoCL compiles kernels into a cache; keep it in a writable place.
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/$BUILD_DIR/pocl-cache}
mkdir -p "$POCL_CACHE_DIR"

# The Python module is built for the pyenv/PATH python3 (its real executable, not a shim).
PYTHON_EXE=$(python3 -c 'import sys; print(sys.executable)')
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE="$PYTHON_EXE" \
  ${ERODEM_CMAKE_ARGS:-}
cmake --build "$BUILD_DIR" --parallel "$(nproc)"
echo "setup: built $BUILD_DIR/cli/erodem"
