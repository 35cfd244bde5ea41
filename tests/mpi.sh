#!/usr/bin/env bash
# erodem — the MPI domain decomposition against the run on one process (ctest Mpi*, label
# `mpi`; registered only with ERODEM_MPI; docs/mpi.md).
#
# Runs one small scenario (a synthetic valley of 37 x 37 cells, 40 adaptive steps, 100 mm/h of
# rain) without mpirun, then under `mpirun -np N` for N = 1, 2, 3, 4 (oversubscribed, one
# OpenMP thread a rank: these prove correctness, not speed), and requires every result to be
# the serial one bit for bit:
#  - `erodem compare --tol 0`: every output field at every snapshot (a relative L2 difference
#    of exactly 0; compare exits 1 on any larger one),
#  - every dataset of the groups /diagnostics (the ledger's volumes, dt, maxima every step),
#    /restart (the full state: fluxes, the bed's residual, the ledger), /gauges and /sections
#    where there are gauges and sections, by tests/h5_rows.py (a run continued from a restart
#    against the reference's last rows) and, where the rows are the same, `h5diff` (the root
#    attributes differ: the command line, the creation time).
# Scenarios (the first argument):
#  - erosion: local inertial + erosion (conservative transport) + thermal, a point inflow,
#    three gauges, an open east edge, a fixed-level south edge, two sections (one along a row,
#    one down a column across every band) and outlets on both open edges (/sections too);
#  - pipes: the pipe model with erosion and thermal, on a diamond-square terrain (each rank
#    makes the lattices of its rows), 400 m of relief and wet ground collapsing at 5 degrees
#    (the wetness, which thermal collapse reads one row away, must reach the one halo row);
#  - shallow_water: second-order shallow water (two stages a step, 2-row halo) with
#    boundary.periodic_x (the periodic columns and the bands' rows together);
#  - shallow_water_edges, shallow_water_order1: the shallow water of the second and of the first
#    order with an open east edge and a fixed-level south edge (on OpenCL's CPU devices the
#    interior rows by the kernels that read the velocities from a pass of their own);
#  - water_cycle: every other process that reads or writes across cells, each of whose halo
#    fields must be exchanged or may not be (process.hpp neighbour_read_fields): local
#    inertial, Mei's erosion law with hardness noise, a snow pack that melts and slides,
#    Green-Ampt infiltration, evaporation, wet thermal collapse, and terrain classes every 5
#    steps whose tables set the Manning n and the talus angle, on 400 m of relief with wet
#    ground collapsing at 5 degrees (the wetness the bands compute on their halo rows);
#  - thin_bands: pipes with erosion and thermal on a window of 5 rows with open north and south
#    edges: bands of one row, whose ghost rows read the bed in their halo row;
#  - restart: the erosion scenario run to step 20 on 3 ranks, continued from that file to
#    step 40 on 2 ranks and on 4, and on one process from a file written by 4 ranks, each
#    against the serial run of 40 steps;
#  - refusals: what N > 1 ranks refuse, each with its exit code and a message naming it:
#    transport.scheme = "semi_lagrangian" (78, on both backends), bands thinner than
#    the halo (4 ranks on 7 rows: 2), and (parallel HDF5, where unshare -m may mount) an
#    output folder rank 1 sees as another, empty folder (73);
#  - row_tail: the erosion scenario's processes (local inertial, erosion, thermal; no inflow,
#    gauges or sections) on a 2061 x 37 window across a valley of 2061 x 2061 cells instead of
#    the small valley: on OpenCL (PoCL) the padded row of 2063 cells has no divisor in
#    [32, 1024], so every row is launched as three groups of 687 and a tail group of two (the
#    last DEM column and the ghost), whose tally partials sit at the top of each slot, and a
#    band's own rows must still write over its halo rows' partials;
#  - dem_rows: a real DEM read by rows (../shared/data/dem/rhine, a 48 x 45 window across the
#    basin's edge on a lat/lon grid, two thirds nodata as sea at 330 m) with a raster for the
#    initial depth, the Manning n, the hardness, the rain factor, the soil (physical erosion)
#    and the snow pack (whose slope limit reads the neighbours' beds), gridded rain and air
#    temperature, boundary codes and a latitude cap: under N > 1 each rank reads only its
#    band's rows and 4 beside them (the log's note says so); and a bad elevation, raster value
#    or boundary code stops every rank with the message and exit code (65) of one process;
#  - dem_rows_coarse: dem_rows averaged 2 x 2 as it is read (dem.resample = 2): each rank reads
#    whole blocks of its coarse rows (without the boundary code of 1.5, which averaging takes
#    as its block's most frequent whole code);
#  - interrupt: a stop signal (SIGTERM, SIGUSR1) to erodem, and to each rank under mpirun 0.5 s
#    apart: exit 130 and a partial file identical to the serial run to the step it names.
# The ranks write their one result file together where the build has parallel HDF5: then they
# run with a TMPDIR that names no folder, so a rank that made a scratch file of its own fails.
# Fails too where a run under mpirun exits non-zero (but the refusals).
# Checked by hand (2026-11-27): with the halo exchange between ranks skipped
# (CpuBackend::exchange_field returning before parallel::exchange), every scenario fails at
# N = 2: `erodem compare` reports rel_L2 of 1e-3 .. 1 on water_depth and the others (see
# docs/mpi.md for the figures).
# BACKEND (the third argument, `cpu` by default): `opencl` runs every scenario but refusals and
# interrupt on the OpenCL backend (PoCL here, each rank its own context) against the serial OpenCL run, bit for bit as on the CPU, twice: with the launches
# of whole rows PoCL gets by default (N = 1, 2, 3, 4), and with ERODEM_OPENCL_WG=64
# (work-groups that do not divide a row, and the statistics' tree reduction: the launches GPUs
# get; N = 3). The bad inputs of dem_rows and dem_rows_coarse, which stop before a backend is
# made, run in the CPU scenario only.
# Exit 77 (skipped) without mpirun, h5diff or Python's h5py, or for `opencl` without an OpenCL
# device.
# Usage: mpi.sh path/to/erodem SCENARIO [BACKEND]
set -euo pipefail
erodem=$(realpath "$1")
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scenario=$2
backend=${3:-cpu}
if [ "$backend" = opencl ] && ! "$erodem" devices 2>/dev/null | grep -q "^  platform "; then
  echo "no OpenCL device: skipped"
  exit 77
fi
for tool in mpirun h5diff; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "$tool not installed (Debian: openmpi-bin, hdf5-tools): skipped"
    exit 77
  fi
done
if ! python3 -c 'import h5py, numpy' 2>/dev/null; then
  echo "python3 without h5py and numpy (tests/h5_rows.py; scripts/setup.sh installs them): skipped"
  exit 77
fi
work=$(mktemp -d)
trap '[ -n "${ERODEM_KEEP_WORK:-}" ] || rm -rf "$work"' EXIT
cd "$work"
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=PASSIVE
mpi=(mpirun --allow-run-as-root --oversubscribe --bind-to none)

cat >scenario.toml <<EOF
[dem]
synthetic = "valley"
size = 37
seed = 7
relief = "150 m"
cell_size = "10 m"

[initial]
water_depth = "5 mm"

[time]
steps = 40
adaptive = true
cfl = 0.7
dt_max = "1 s"

[rain]
rate = "100 mm/h"

[erosion]
enabled = true

[thermal]
enabled = true
talus_angle = 30.0

[output]
every = 10
EOF
sets=()
case $scenario in
  erosion | restart)
    cat >>scenario.toml <<EOF
gauges = [[155.0, 155.0], [35.0, 305.0], [305.0, 45.0]]

[flow]
scheme = "local_inertial"

[boundary]
east = "open"
south = "fixed_level"
sea_level = 20.0

[[inflow]]
point = [185.0, 195.0]
hydrograph = [[0, 0.5], [40, 2.0]]

[[section]]
name = "across"
line = [[5.0, 185.0], [365.0, 185.0]]

[[section]]
name = "down"
line = [[185.0, 365.0], [185.0, 5.0]]

[[outlet]]
name = "east"
edge = "east"

[[outlet]]
name = "south"
edge = "south"
EOF
    ;;
  pipes)
    # wet ground collapsing at 5 degrees: the wetness, which thermal collapse reads one row
    # away, must be sent with a halo of one row (no cells sweep computes a halo row there)
    sets=(--set flow.scheme=pipes --set boundary.east=open --set dem.synthetic=diamond_square
      --set dem.relief=400 --set thermal.wet_talus_angle=5 --set thermal.wet_threshold=0.003
      --set numerics.wetness_time=20)
    ;;
  water_cycle)
    # steep (400 m) and wet ground collapsing at 5 degrees within the 40 s, so that the
    # wetness, which the bands compute on their halo rows instead of receiving it, matters at
    # their edges (with evaporation skipping the halo rows, np 3 fails)
    sets=(--set erosion.law=mei --set erosion.hardness=noise --set erosion.noise_scale=100
      --set snow.enabled=true --set snow.initial=0.05 --set snow.air_temperature=3
      --set snow.slide_angle=20 --set snow.slide_rate=0.01 --set infiltration.enabled=true
      --set evaporation.rate=1e-4 --set thermal.wet_talus_angle=5 --set thermal.wet_threshold=0.003
      --set numerics.wetness_time=20 --set dem.relief=400
      --set terrain_classes.enabled=true --set terrain_classes.interval=5
      --set terrain_classes.grass.manning_n=0.04 --set terrain_classes.rock.talus_angle=40
      --set terrain_classes.mud.manning_n=0.05)
    ;;
  shallow_water)
    sets=(--set flow.scheme=shallow_water --set flow.order=2 --set boundary.periodic_x=true)
    ;;
  shallow_water_edges | shallow_water_order1)
    # an open east edge and a fixed-level south edge instead of periodic columns (ghost columns
    # that are not active cells, which the interior kernels read across the row ends on CPU
    # devices)
    sets=(--set flow.scheme=shallow_water --set boundary.east=open --set boundary.south=fixed_level
      --set boundary.sea_level=20)
    if [ "$scenario" = shallow_water_edges ]; then
      sets+=(--set flow.order=2)
    else
      sets+=(--set flow.order=1)
    fi
    ;;
  thin_bands)
    # pipes (a halo of one row) on a window of 5 rows: bands of one row at np 3 and 4, whose
    # open north and south ghost rows read the bed two rows inside, in the halo row beyond
    # their own (the bed after thermal collapse must be sent: exact_in_band, the boundary's
    # reach; with it skipped np 3 and 4 differ)
    "$erodem" generate --kind valley --size 40 --seed 7 --relief 300 thin_valley.tif >/dev/null
    sed -i '/^synthetic = /,/^cell_size = /c\path = "thin_valley.tif"\nwindow = [0, 10, 40, 5]' \
      scenario.toml
    sets=(--set flow.scheme=pipes --set boundary.north=open --set boundary.south=open
      --set boundary.east=open)
    ;;
  row_tail)
    # the valley's [dem] lines (synthetic .. cell_size) replaced by a window across a wider one
    "$erodem" generate --kind valley --size 2061 --seed 7 --relief 150 wide_valley.tif >/dev/null
    sed -i '/^synthetic = /,/^cell_size = /c\path = "wide_valley.tif"\nwindow = [0, 1000, 2061, 37]' \
      scenario.toml
    ;;
  dem_rows | dem_rows_coarse)
    # a real DEM (../shared/data/dem) read by rows: a window across the Rhine basin's western
    # edge, two thirds nodata (sea at 330 m: coast cells on every band), on a lat/lon grid,
    # with every parameter raster a band reads by rows (each a linear map of the elevations)
    rhine="$here/../../shared/data/dem/rhine/rhine_elv0.tif"
    if [ ! -f "$rhine" ]; then
      echo "FAIL: $rhine is missing (../shared/data/dem beside the repository)"
      exit 1
    fi
    scaled() { # NAME LOW HIGH: the elevations 280 .. 480 m mapped onto LOW .. HIGH
      gdal_translate -q -ot Float32 -a_nodata none -scale 280 480 "$2" "$3" "$rhine" "$1.tif"
    }
    scaled manning 0.02 0.08
    scaled hardness 0.2 0.9
    scaled rain 0.5 2
    scaled soil 0.5 3
    scaled snow 0 0.1
    scaled depth 0 0.01
    # gridded rain (3 bands 10 s apart, mm/h) and air temperature (2 bands 20 s apart, C)
    scaled rain1 0 200
    scaled rain2 200 0
    scaled rain3 50 60
    scaled air1 -5 5
    scaled air2 5 -5
    gdalbuildvrt -q -separate rains.vrt rain1.tif rain2.tif rain3.tif
    gdal_translate -q rains.vrt rains.tif
    gdalbuildvrt -q -separate airs.vrt air1.tif air2.tif
    gdal_translate -q airs.vrt airs.tif
    # boundary codes: closed (1) on the cells of 400 .. 410 m, fixed_level on their own bed (3)
    # above 440 m, as the edge says (0) elsewhere
    gdal_calc.py --quiet -A "$rhine" --outfile=codes.tif --type=Float32 \
      --calc="where(A > 440, 3, where((A > 400) * (A <= 410), 1, 0))"
    sed -i '/^synthetic = /,/^cell_size = /c\path = "'"$rhine"'"\nwindow = [200, 440, 48, 45]' \
      scenario.toml
    # what is asked of cells on any rank's rows (terrain_rows.hpp: each rank's mask holds its
    # band's rows): gauges on land of each rank of 4, on nodata and on a closed code; an
    # inflow at a point and along a line across three bands and the nodata; an outlet at a
    # coast cell and one along the east edge (nodata, capped and coded cells among its rows)
    cat >>scenario.toml <<EOF
gauges = [[5.570833, 48.004167], [5.279167, 48.170833], [5.570833, 48.220833],
  [5.529167, 48.2625], [5.4875, 47.995833], [5.6125, 48.204167], [5.6125, 48.129167]]

[[inflow]]
point = [5.5875, 48.045833]
hydrograph = [[0, 0.5], [40, 2.0]]

[[inflow]]
line = [[5.529167, 48.2625], [5.504167, 48.0875], [5.3, 48.1]]
hydrograph = [[0, 0.2], [40, 0.1]]

[[outlet]]
name = "coast"
point = [5.5125, 48.120833]

[[outlet]]
name = "east"
edge = "east"
EOF
    sed -i 's/^rate = "100 mm\/h"/raster = "rain.tif"/' scenario.toml
    sed -i 's/^water_depth = "5 mm"/water_depth = "depth.tif"/' scenario.toml
    sets=(--set boundary.nodata=sea --set boundary.sea_level=330 --set flow.manning_n=manning.tif
      --set erosion.law=physical --set erosion.soil_thickness=soil.tif
      --set erosion.hardness=hardness.tif --set snow.enabled=true --set snow.initial=snow.tif
      --set snow.max_slope=2 --set rain.grids=rains.tif --set rain.grid_interval=10
      --set snow.temperature_grids=airs.tif --set snow.temperature_grid_interval=20
      --set boundary.raster=codes.tif --set boundary.latitude_cap=48.3)
    # averaged 2 x 2 as it is read (24 x 22 cells): each rank reads the blocks of its rows;
    # there the hardness is noise scaled to the range of every rank's active cells, and the
    # adaptive step is left to its CFL limits (100 to 600 s), the narrowest active row's
    # (with the latitude cap every rank must find the grid's, not its band's: checked by hand
    # with each rank's own rows, np 2 gives another dt)
    [ "$scenario" = dem_rows ] || sets+=(--set dem.resample=2 --set erosion.hardness=noise
      --set erosion.noise_scale=3000 --set time.dt_max=100000)
    ;;
  refusals | interrupt) ;;
  *)
    echo "unknown scenario '$scenario' (erosion, pipes, shallow_water, shallow_water_edges," \
      "shallow_water_order1, water_cycle, thin_bands, row_tail, dem_rows, dem_rows_coarse, restart," \
      "refusals, interrupt)"
    exit 2
    ;;
esac

failed=0
# same_as REFERENCE RESULT LABEL [continued]: the comparisons above; failed=1 on any
# difference; `continued`: RESULT is a run continued from a restart file. Every
# dataset of /diagnostics, /restart, /gauges and /sections by tests/h5_rows.py: a run continued
# from a restart file holds only the steps and snapshots from there on, compared with the
# reference's last rows (h5diff calls datasets of other lengths "not comparable" and exits 0:
# before 2026-11-29 the restart runs' groups were not compared at all), and by h5diff where no
# tolerance applies (the attributes too). On OpenCL the fields, gauges, sections and the restart state are compared
# bit for bit as on the CPU, the ledger within the rounding of its sums (h5_rows.py --ledger:
# tallies and volumes within a relative 1e-12, relative closures within 1e-12, closures within
# 1e-9 m^3, 3e-13 of the 3,400 m^3 this scenario moves): each rank sums its own rows' tallies
# on the device (a tree over the work-groups' partials), and the ranks' sums are added in rank
# order, while one process sums every row's partials in one tree (measured: one
# relative_material_closure_error differs by 2.4e-20 at np 3, shallow water). A tally that
# missed or doubled a band's halo rows would be off by a few per cent.
same_as() {
  local ref=$1 out=$2 label=$3 continued=${4:-} rc=0 g groups=(/diagnostics /restart) opts
  "$erodem" compare "$out" "$ref" --tol 0 >compare.txt 2>&1 || rc=$?
  if [ $rc -ne 0 ]; then
    echo "FAIL $label: erodem compare --tol 0 exit $rc:"
    cat compare.txt
    failed=1
  fi
  for g in /gauges /sections; do
    if h5diff -q "$ref" "$ref" $g $g >/dev/null 2>&1; then groups+=($g); fi
  done
  # (one h5_rows.py for every group: --ledger applies to /diagnostics and /restart only)
  local rows_opts=()
  [ "$backend" != opencl ] || rows_opts+=(--ledger)
  [ -z "$continued" ] || rows_opts+=(--continued)
  if ! python3 "$here/h5_rows.py" "$ref" "$out" "${groups[@]}" "${rows_opts[@]}" >rows.txt 2>&1; then
    echo "FAIL $label: ${groups[*]} differ (h5_rows.py ${rows_opts[*]}):"
    head -20 rows.txt
    failed=1
    rc=1
  fi
  for g in "${groups[@]}"; do
    opts=()
    if [ "$backend" = opencl ] && [ $g = /diagnostics -o $g = /restart ]; then opts=(--ledger); fi
    if [ ${#opts[@]} -eq 0 ] && ! h5diff "$ref" "$out" "$g" "$g" >h5diff.txt 2>&1; then
      echo "FAIL $label: $g differs (h5diff):"
      head -20 h5diff.txt
      failed=1
      rc=1
    fi
  done
  # the measured figure: the largest relative L2 difference of any field
  local worst
  worst=$(awk '$NF == "ok" || $NF == "FAIL" {print $3}' compare.txt | sort -g | tail -1)
  local what="${groups[*]} $([ $rc -eq 0 ] && echo identical || echo DIFFER)"
  if [ "$backend" = opencl ] && [ $rc -eq 0 ]; then
    what="$what (the ledger within its rounding)"
  fi
  echo "$label: largest rel_L2 ${worst:-?} (tolerance 0), $what"
}
run() { # LABEL OUTPUT [mpirun -np N] -- ARGS...
  local label=$1 out=$2 rc=0
  shift 2
  "$@" --backend "$backend" --output "$out" --overwrite "${sets[@]}" >"$out.log" 2>&1 || rc=$?
  if [ $rc -ne 0 ]; then
    echo "FAIL $label: exit $rc ($*):"
    tail -5 "$out.log"
    exit 1
  fi
}

# refused NAME CODE TEXT ARGS...: a run under mpirun -np 2 (4 where ARGS start with "-np 4")
# that must exit CODE with TEXT in its message
refused() {
  local label=$1 code=$2 text=$3 np=2 rc=0
  shift 3
  if [ "$1" = "-np" ]; then
    np=$2
    shift 2
  fi
  "${mpi[@]}" -np "$np" "$erodem" run scenario.toml --output refused.h5 --overwrite "$@" \
    >refused.log 2>&1 || rc=$?
  if [ $rc -ne "$code" ] || ! grep -qF -- "$text" refused.log; then
    echo "FAIL $label: exit $rc (expected $code), message:"
    grep "^erodem:" refused.log | head -2
    failed=1
  else
    echo "$label: exit $rc, $(grep -m1 "^erodem:" refused.log)"
  fi
}

if [ "$scenario" = refusals ]; then
  refused "semi-Lagrangian transport" 78 'transport.scheme = "semi_lagrangian": not supported' \
    --backend cpu --set transport.scheme=semi_lagrangian
  if "$erodem" devices 2>/dev/null | grep -q "^  platform "; then
    refused "semi-Lagrangian transport on OpenCL" 78 \
      'transport.scheme = "semi_lagrangian": not supported' --backend opencl \
      --set transport.scheme=semi_lagrangian
  fi
  refused "bands thinner than the halo" 2 "each rank needs at least 2" -np 4 --backend cpu \
    --set dem.size=7
  # Only `erodem run` is decomposed: `erodem bench` under mpirun runs its whole grid in each
  # process (before 2026-11-29 each ran a band and reported it as the whole grid's rate).
  rc=0
  timeout 120 "${mpi[@]}" -np 2 "$erodem" bench --size 48 --steps 1 --backends cpu \
    --stream-floats 65536 >bench.log 2>&1 || rc=$?
  if [ $rc -ne 0 ] || [ "$(grep -c "^  cpu/all    CPU reference" bench.log)" != 2 ] ||
    grep -q "MPI ranks in bands" bench.log; then
    echo "FAIL erodem bench under mpirun -np 2: exit $rc (expected 0, two whole-grid benches), log:"
    grep -m2 "cpu/all    CPU\|erodem" bench.log
    failed=1
  else
    echo "erodem bench under mpirun -np 2: exit 0, each process the whole grid: $(grep -m1 "cpu/all    CPU" bench.log | sed 's/^ *//')"
  fi
  # `--backend auto` where one rank would pick OpenCL and the other the CPU reference (rank 1
  # names PoCL in ERODEM_OPENCL_DEVICE): every rank must run the CPU reference, and say why
  # (the two backends' collectives differ: mixed, the ranks wait for each other for ever).
  if "$erodem" devices 2>/dev/null | grep -q "^  platform "; then
    printf '%s\n' '#!/bin/sh' \
      'if [ "${OMPI_COMM_WORLD_RANK:-0}" = 1 ]; then export ERODEM_OPENCL_DEVICE=":"; fi' \
      'exec "$@"' >mixed.sh
    rc=0
    timeout 120 "${mpi[@]}" -np 2 sh mixed.sh "$erodem" run scenario.toml --output mixed.h5 \
      --overwrite --backend auto >mixed.log 2>&1 || rc=$?
    if [ $rc -ne 0 ] || ! grep -q "not every one of the 2 MPI ranks has an OpenCL GPU" mixed.log ||
      ! "$erodem" info mixed.h5 2>/dev/null | grep -q "CPU reference"; then
      echo "FAIL auto with an OpenCL device on one rank only: exit $rc (expected 0), log:"
      grep -m3 "erodem\|auto" mixed.log
      failed=1
    else
      echo "auto with an OpenCL device on one rank only: exit 0, $(grep -m1 -o "auto: .*" mixed.log | cut -c1-100)"
    fi
  fi
  # An output folder that is not one folder for every rank: rank 1 runs in a mount namespace
  # of its own (unshare -m) with an empty tmpfs over ./shared, as a node-local disk would be.
  # Exit 73 naming the folder and rank 1, and nothing left in the folder. Needs parallel HDF5
  # (else rank 0 alone writes the file) and the right to mount (root, CAP_SYS_ADMIN).
  mkdir -p shared
  if "$erodem" --version | grep -q "parallel HDF5" &&
    unshare -m sh -c 'mount -t tmpfs none shared' 2>/dev/null; then
    cat >private.sh <<'EOF'
#!/bin/sh
# rank 1 of mpirun runs "$@" with a private, empty tmpfs over ./shared
if [ "${OMPI_COMM_WORLD_RANK:-0}" = 1 ]; then
  exec unshare -m sh -c 'mount -t tmpfs none shared && exec "$@"' sh "$@"
fi
exec "$@"
EOF
    # (without the check the ranks wait for each other for ever: 124 here)
    rc=0
    timeout 120 "${mpi[@]}" -np 2 sh private.sh "$erodem" run scenario.toml \
      --output shared/out.h5 --backend cpu >private.log 2>&1 || rc=$?
    if [ $rc -ne 73 ] || [ -n "$(ls -A shared)" ] ||
      ! grep -qF "'shared' is not one folder shared by every MPI rank (rank 1 of 2" private.log; then
      echo "FAIL output folder not shared: exit $rc (expected 73), shared/ holds:" \
        "$(ls -A shared | tr '\n' ' '), message:"
      grep "^erodem:" private.log | head -2
      failed=1
    else
      echo "output folder not shared: exit $rc, shared/ left empty, $(grep -m1 "^erodem:" private.log)"
    fi
  else
    echo "output folder not shared: not checked (needs parallel HDF5 and a tmpfs mounted by unshare -m)"
  fi
elif [ "$scenario" = interrupt ]; then
  # A stop signal ends a long run at a step every rank agrees on: exit 130, one message (rank
  # 0's) naming the step N, and a partial file identical to the serial run of N steps
  # (snapshots, diagnostics, restart state: same_as). Without mpirun: SIGTERM to erodem. Under
  # mpirun: the signal to each rank 0.5 s apart (as a batch system's signal reaches the ranks
  # of several nodes; this OpenMPI's mpirun passes no SIGUSR1 on), steps apart here, so the
  # ranks must agree on the step; without that they wait for each other for ever.
  stopped() { # LABEL OUT SIGNAL N COMMAND...: COMMAND (a run of a million steps, N processes)
    # in the background, then SIGNAL to each of its processes
    local label=$1 out=$2 sig=$3 count=$4 rc=0 partial="" n=""
    shift 4
    "$@" run scenario.toml --backend cpu --output "$out" --overwrite --set time.steps=1000000 \
      --set output.every=500 >"$out.log" 2>&1 &
    local pid=$!
    (sleep 90 && { pkill -9 -P $pid; kill -9 $pid; }) >/dev/null 2>&1 &
    local watchdog=$!
    # the processes to signal (the ranks: mpirun's children), once each catches SIGNAL (its
    # handler is installed when the time loop starts: /proc/PID/status SigCgt)
    local targets=() number ready
    number=$(kill -l "$sig")
    for _ in $(seq 600); do
      if [ "$1" = "$erodem" ]; then targets=($pid); else mapfile -t targets < <(pgrep -P $pid || true); fi
      ready=${#targets[@]}
      for t in "${targets[@]}"; do
        mask=$(awk '/^SigCgt/ {print $2}' /proc/$t/status 2>/dev/null || true)
        if [ -z "$mask" ] || (((16#$mask >> (number - 1) & 1) == 0)); then ready=0; fi
      done
      [ "$ready" -eq "$count" ] && break
      sleep 0.1
    done
    sleep 0.5
    for t in "${targets[@]}"; do
      kill -$sig $t 2>/dev/null || true
      sleep 0.5
    done
    wait $pid || rc=$?
    pkill -P $watchdog 2>/dev/null || true
    n=$(grep -o "interrupted at step [0-9]*" "$out.log" | grep -o "[0-9]*$" || true)
    partial=$(ls .$out.*.partial 2>/dev/null | head -1 || true)
    if [ $rc -ne 130 ] || [ -z "$n" ] || [ -z "$partial" ] ||
      [ "$(grep -c "interrupted at step" "$out.log")" -ne 1 ]; then
      echo "FAIL $label: exit $rc (expected 130), step '${n}', partial file '${partial}', log:"
      tail -5 "$out.log"
      failed=1
      return
    fi
    if [ "$n" -eq 0 ]; then # stopped before the first step (a very slow start): nothing to compare
      echo "$label: exit $rc at step 0, before the first step: no comparison"
      return
    fi
    run "serial, $n steps" "ref_$out" "$erodem" run scenario.toml --set time.steps="$n" \
      --set output.every=500
    echo "$label: exit $rc at step $n ($(grep -m1 "interrupted at step" "$out.log" | cut -c1-60)...)"
    same_as "ref_$out" "$partial" "$label, the partial file against the serial run of $n steps"
  }
  stopped "SIGTERM, no mpirun" int1.h5 TERM 1 "$erodem"
  stopped "SIGUSR1 to each of 2 ranks" int2.h5 USR1 2 "${mpi[@]}" -np 2 "$erodem"
  stopped "SIGTERM to each of 3 ranks" int3.h5 TERM 3 "${mpi[@]}" -np 3 "$erodem"
elif [ "$scenario" = restart ]; then
  run serial serial.h5 "$erodem" run scenario.toml
  run "np 3, 20 steps" first3.h5 "${mpi[@]}" -np 3 "$erodem" run scenario.toml --set time.steps=20
  run "np 4, 20 steps" first4.h5 "${mpi[@]}" -np 4 "$erodem" run scenario.toml --set time.steps=20
  for n in 2 4; do
    run "np $n from np 3" rest$n.h5 "${mpi[@]}" -np $n "$erodem" run scenario.toml --restart first3.h5
    same_as serial.h5 rest$n.h5 "restart np 3 -> np $n" continued
  done
  run "one process from np 4" rest1.h5 "$erodem" run scenario.toml --restart first4.h5
  same_as serial.h5 rest1.h5 "restart np 4 -> no mpirun" continued
else
  # With parallel HDF5 (`erodem --version` says so) the ranks write the one result file
  # together and none needs a file of its own: they run with TMPDIR naming no folder, where the
  # serial-HDF5 build's scratch files (and the writer of before 2026-11-27) fail to be created.
  tmp=()
  if "$erodem" --version | grep -q "parallel HDF5"; then
    tmp=(env TMPDIR="$work/no-such-folder")
  fi
  # the launch kinds: one on the CPU; OpenCL's whole rows (PoCL's default) and rounded
  # work-groups of 64 (ERODEM_OPENCL_WG, as on GPUs), each against its own serial run
  kinds=("")
  if [ "$backend" = opencl ]; then kinds=("" 64); fi
  for wg in "${kinds[@]}"; do
    export ERODEM_OPENCL_WG=$wg
    label="$scenario on $backend${wg:+ (work-groups of $wg)}"
    run serial serial.h5 "$erodem" run scenario.toml
    # (the rounded launches at np 3 only: a band with a halo on either side and the two edge
    # bands; they change how each rank's kernels cover its rows, not what the ranks exchange,
    # which the whole-row launches check at 1 to 4 ranks)
    nps=(1 2 3 4)
    [ -z "$wg" ] || nps=(3)
    for n in "${nps[@]}"; do
      # (dem_rows at np 3: every gather, of the coast cells and the first bad cells, 100 bytes
      # a rank at a time, as a gather of more than 2 GiB runs: parallel::allgather_bytes)
      gather=()
      [ "$scenario" = dem_rows ] && [ $n = 3 ] && gather=(-x ERODEM_MPI_GATHER_BYTES=100)
      run "np $n" np$n.h5 "${mpi[@]}" -np $n "${gather[@]}" "${tmp[@]}" "$erodem" run scenario.toml
      same_as serial.h5 np$n.h5 "$label, np $n"
      # what the run prints of the whole grid (the active area under the physical law, the
      # outlets) as one process prints it
      if ! diff <(grep -E "^(sediment \(solid|outlet |section )" serial.h5.log) \
        <(grep -E "^(sediment \(solid|outlet |section )" np$n.h5.log) >/dev/null; then
        echo "FAIL $label, np $n: the summary differs from one process's:"
        grep -E "^(sediment \(solid|outlet |section )" np$n.h5.log
        failed=1
      fi
      # each rank read or made only its rows of the terrain (the note load_terrain leaves)
      if [ $n -gt 1 ] && ! grep -Eq "each of the $n ranks (read|made) its own rows" np$n.h5.log; then
        echo "FAIL $label, np $n: the ranks did not read or make the terrain by rows (no note in the log)"
        failed=1
      fi
    done
  done
  if [ "$scenario" = dem_rows ] || [ "$scenario" = dem_rows_coarse ]; then
    # A bad value is found by the rank owning its row, and every rank stops with the message
    # and exit code one process gives (the first bad cell in row order: io/src/setup.cpp
    # first_bad_cell): elevations beyond 440 m (the first on row 15, rank 1's of 3 and of 4;
    # rank 2 of 4 holds more), an initial depth raster below 0 on every band, and a boundary
    # code of 1.5 (no code) on the cells beyond 440 m. Checked by
    # hand: with each rank naming its own first bad cell (no allgather), np 4 names cell (31,
    # 23) of rank 2 and fails here.
    scaled negative -1 0.01
    gdal_calc.py --quiet -A "$rhine" --outfile=codes_half.tif --type=Float32 \
      --calc="where(A > 440, 1.5, 0)"
    # Each case: the settings (separated by |), and the exit code one process gives.
    bads=("dem.elevation_limit=440|65" "initial.water_depth=negative.tif|65"
      # (no row is chosen before reading where the resample factor is an error, or leaves no
      # row: every rank reads the whole grid and meets the error where one process does, after
      # the data's checks; review of 2026-11-29)
      "dem.resample=1500 m|dem.elevation_limit=440|65"
      "dem.window=[200, 440, 48, 3]|dem.resample=4|78"
      # (a window of nodata alone: read_dem's message)
      "dem.window=[0, 0, 20, 20]|65")
    # (averaged, a block takes its most frequent whole code: 1.5 counts as 1, no error)
    [ "$scenario" = dem_rows_coarse ] || bads+=("boundary.raster=codes_half.tif|65")
    # (these runs stop while the ranks read their rows, before a backend is made, and name no
    # backend: the OpenCL scenario would repeat the CPU one's runs)
    [ "$backend" = cpu ] || bads=()
    for bad in "${bads[@]}"; do
      IFS='|' read -ra parts <<<"$bad"
      code=${parts[-1]}
      args=()
      for part in "${parts[@]:0:${#parts[@]}-1}"; do args+=(--set "$part"); done
      for n in 1 3 4; do
        rc=0
        if [ $n = 1 ]; then
          "$erodem" run scenario.toml "${sets[@]}" "${args[@]}" --output bad$n.h5 --overwrite \
            >bad$n.log 2>&1 || rc=$?
        else
          "${mpi[@]}" -np $n "$erodem" run scenario.toml "${sets[@]}" "${args[@]}" \
            --output bad$n.h5 --overwrite >bad$n.log 2>&1 || rc=$?
        fi
        message=$(grep -m1 "^erodem:" bad$n.log || true)
        [ $n = 1 ] && first="$message"
        # (and no file is left behind: no result, no partial file of any rank)
        left=$(ls -A | grep -E "^(bad$n\.(h5|xmf)|\.bad$n\.h5\..*partial)$" || true)
        if [ $rc -ne "$code" ] || [ -z "$message" ] || [ "$message" != "$first" ]; then
          echo "FAIL ${args[*]}, np $n: exit $rc, '$message' (one process: exit $code, '$first')"
          failed=1
        elif [ -n "$left" ]; then
          echo "FAIL ${args[*]}, np $n: left $left behind"
          failed=1
        else
          echo "${args[*]}, np $n: exit $code, $message"
        fi
      done
    done
    # a synthetic terrain averaged as it is made (38 rows, 2 x 2: each rank makes whole blocks
    # of its coarse rows and 4 coarse rows beside them; review of 2026-11-29)
    cat >synth.toml <<EOF
[dem]
synthetic = "hill"
size = 38
seed = 3
relief = "150 m"
cell_size = "10 m"
resample = 2

[time]
steps = 20

[rain]
rate = "100 mm/h"

[erosion]
enabled = true
EOF
    "$erodem" run synth.toml --backend "$backend" --output synth1.h5 >synth1.log 2>&1 ||
      { echo "FAIL synthetic hill, averaged: $(tail -1 synth1.log)"; failed=1; }
    for n in 2 3; do
      "${mpi[@]}" -np $n "$erodem" run synth.toml --backend "$backend" --output synth$n.h5 \
        >synth$n.log 2>&1 || { echo "FAIL synthetic hill, averaged, np $n: $(tail -1 synth$n.log)"; failed=1; }
      same_as synth1.h5 synth$n.h5 "synthetic hill of 38 rows averaged 2 x 2, np $n"
    done
    # the latitude cap without boundary.raster: at np 3 ranks 1 and 2 hold no capped row (rows
    # 11 to 44 of 45, the cap's 5 rows on top) and must still check the codes the cap gives
    # with rank 0 (a review of 2026-11-29: with codes only where a capped row is held, np 3
    # waited for ever in a gather)
    nocodes=()
    for ((k = 0; k < ${#sets[@]}; k += 2)); do
      [ "${sets[k + 1]}" = boundary.raster=codes.tif ] || nocodes+=("${sets[k]}" "${sets[k + 1]}")
    done
    "$erodem" run scenario.toml --backend "$backend" --output cap1.h5 "${nocodes[@]}" \
      >cap1.log 2>&1 || { echo "FAIL latitude cap without codes: $(tail -1 cap1.log)"; failed=1; }
    for n in 2 3; do
      timeout 300 "${mpi[@]}" -np $n "$erodem" run scenario.toml --backend "$backend" \
        --output cap$n.h5 "${nocodes[@]}" >cap$n.log 2>&1 ||
        { echo "FAIL latitude cap without codes, np $n: exit $? $(tail -1 cap$n.log)"; failed=1; }
      same_as cap1.h5 cap$n.h5 "latitude cap without boundary.raster, np $n"
    done
  fi
  echo "$("$erodem" --version): $([ ${#tmp[@]} -gt 0 ] && echo "one file written by the ranks together, no scratch file (TMPDIR names no folder)" || echo "rank 0 writes, the others into scratch files")"
fi
exit $failed
