#!/usr/bin/env bash
# erodem — the OpenCL kernels under Oclgrind (ctest Oclgrind, label `oclgrind`).
#
# Oclgrind simulates an OpenCL 1.2 device and checks every memory access of every work-item:
# an out-of-bounds or otherwise invalid read or write, and, with --data-races, two work-items
# of a launch touching the same address without a barrier between them. PoCL runs the same
# kernels without such checks, and a GPU driver would only show wrong numbers. This test runs a
# small scenario with every process on under `oclgrind --data-races` (its memory checker is
# always on): 48 x 48 cells of a synthetic valley, 200 adaptive steps (t = 200 s), local-
# inertial flow from a wet start under 100 mm/h of rain, the physical erosion law with
# conservative transport, thermal collapse (a dry and a wet talus angle), evaporation, a snow
# pack that melts, takes rain, then snowfall as the air cools below 1 degree C, and slides,
# Green-Ampt infiltration, terrain classes every 5 steps (all five classes occur) with class
# tables of Manning n, talus angle and erodibility, and an open east edge with an outlet. On
# the CPU every one of them moves water or material (the ledger: 934 m^3 collapsed, 110 m^3
# eroded, 14 m^3 melted, 446 m^3 of snowfall, 721 m^3 infiltrated, 18 m^3 evaporated). It fails
#  - on any error Oclgrind reports (its log is printed),
#  - on a non-zero exit of the run, which includes the abort at exit that releasing the
#    OpenCL objects during static destruction caused under Oclgrind (exit 134, "corrupted
#    double-linked list"; backends.hpp, release_opencl_runtimes),
#  - when the result differs from the CPU reference's (float32): `erodem compare --tol 0`
#    over the five snapshots of all 18 output fields (a relative L2 difference of exactly 0:
#    every value equal).
# Oclgrind's --uninitialized plugin (21.10) crashes inside itself, so it is left out.
# Measured 2026-11-27 (Oclgrind 21.10, Debian bookworm, 2 vCPUs shared): no error reported,
# exit 0, every field of every snapshot bit-identical to the CPU reference; see
# docs/testing.md for the time.
# Exit 77 (skipped) without oclgrind or without the OpenCL backend.
# Since 2026-11-28 it runs the scenario three times: as above, and without the terrain classes
# (Manning n and the hardness uniform: one row on both backends) with local inertial and with
# the pipes. With a one-row Manning n of W values (not W + 1) the second run reports 2,240
# invalid reads (the face pass reads column x + 1 of the last column too).
# Usage: oclgrind.sh path/to/erodem [STEPS [SIZE]]: the scenario above by default (200 steps of
# 48 x 48, about 5 minutes of CPU time per run); ctest runs its fast version, 20 steps of
# 32 x 32 with the same processes and the cooling at the same fraction of the run (about 25 s
# per run on an idle machine), so the suite stays within its 30 minutes.
set -euo pipefail
erodem=$1
steps=${2:-200}
size=${3:-48}
cool_start=$((steps * 6 / 10))
cool_end=$((steps * 7 / 10))
every=$((steps / 4))
if ! command -v oclgrind >/dev/null 2>&1; then
  echo "oclgrind not installed (Debian: apt-get install oclgrind): skipped"
  exit 77
fi
if ! "$erodem" devices --json 2>/dev/null | grep -q '"opencl_built": *true'; then
  echo "erodem built without the OpenCL backend: skipped"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
# One run of the scenario under Oclgrind and the CPU reference: run_case NAME SCHEME CLASSES
# (flow.scheme; terrain_classes.enabled). With the classes on, Manning n and the hardness are
# held per cell; with them off they are uniform, one row on both backends (architecture.md
# "Uniform parameters"), which the kernels read at param_index with pitch 0.
run_case() {
local name=$1 scheme=$2 classes=$3 classes_toml=""
if [[ $classes == true ]]; then
  classes_toml='[terrain_classes]
enabled = true
interval = 5
water_wetness = "5 cm"
mud_wetness = "5 mm"
rock_slope = 0.4
grass.manning_n = 0.04
rock.talus_angle = 32.0
mud.erodibility = 0.8'
fi
echo "== $name: flow.scheme = $scheme, terrain_classes.enabled = $classes"
cat >"$work/scenario.toml" <<EOF
[dem]
synthetic = "valley"
size = $size
seed = 7
relief = "150 m"
cell_size = "10 m"

[initial]
water_depth = "5 mm"

[time]
steps = $steps
adaptive = true
cfl = 0.7
dt_max = "1 s"

[flow]
scheme = "$scheme"

[rain]
rate = "100 mm/h"

[erosion]
enabled = true

[transport]
scheme = "conservative"

[thermal]
enabled = true
talus_angle = 30.0
wet_talus_angle = 25.0
wet_threshold = "2 mm"

[evaporation]
rate = 1e-4

[snow]
enabled = true
initial = "5 cm"
snow_line = "80 m"
transition = "20 m"
air_temperature = [[0, 3.0], [$cool_start, 3.0], [$cool_end, 0.0]]
slide_angle = 20.0

[infiltration]
enabled = true

$classes_toml

[numerics]
wetness_time = "60 s"

[boundary]
east = "open"

[[outlet]]
name = "outlet"
edge = "east"

[output]
every = $every
fields = ["bed", "water_depth", "sediment", "velocity_x", "velocity_y", "flux_left",
          "flux_right", "flux_top", "flux_bottom", "hardness", "wetness", "erosion", "snow",
          "snow_liquid", "shear_stress", "soil_thickness", "infiltrated", "terrain_class"]
EOF
# Oclgrind's device only (it replaces the OpenCL library it runs the program with); a device
# choice or work-group size of the caller's would change what is checked.
export ERODEM_OPENCL_DEVICE="Oclgrind:"
unset ERODEM_OPENCL_WG
rm -f "$work/oclgrind.log" "$work/opencl.h5" "$work/cpu.h5"
start=$(date +%s%N)
set +e
oclgrind --data-races --log "$work/oclgrind.log" \
  "$erodem" run "$work/scenario.toml" --backend opencl --output "$work/opencl.h5" \
  >"$work/opencl.out" 2>&1
rc=$?
set -e
ms=$((($(date +%s%N) - start) / 1000000))
printf 'oclgrind --data-races erodem run: exit %d after %d.%01d s; its CPU time (user, system):\n' \
  "$rc" $((ms / 1000)) $((ms % 1000 / 100))
times >"$work/times" # (in a pipeline it would time a subshell)
tail -1 "$work/times"
if ((rc != 0)); then
  echo "FAILED: the run under Oclgrind exited $rc:"
  tail -20 "$work/opencl.out"
  status=1
fi
# Oclgrind writes nothing to its log but what it reports (the kernel compiler's warnings go to
# the run's output).
if [[ -s "$work/oclgrind.log" ]]; then
  echo "FAILED: Oclgrind reported $(grep -c . "$work/oclgrind.log") lines:"
  head -60 "$work/oclgrind.log"
  status=1
else
  echo "Oclgrind reported no invalid access and no data race"
fi
if ((rc == 0)); then
  "$erodem" run "$work/scenario.toml" --backend cpu --output "$work/cpu.h5" >"$work/cpu.out" 2>&1 ||
    {
      echo "FAILED: the CPU reference run failed:"
      tail -20 "$work/cpu.out"
      status=1
      return
    }
  echo "OpenCL on Oclgrind against the CPU reference (float32), every snapshot, bound: bit-identical"
  if ! "$erodem" compare "$work/opencl.h5" "$work/cpu.h5" --tol 0; then
    echo "FAILED: the fields differ from the CPU reference's"
    status=1
  fi
fi
}
run_case "every process, terrain classes" local_inertial true
# The parameters uniform (one row, pitch 0): the local-inertial face pass reads Manning n at
# column x + 1 for every x (the padded row's last column too), and the pipes write their
# outflows in place (a data race between work-items would show here).
run_case "uniform parameters" local_inertial false
run_case "uniform parameters, pipes" pipes false
exit $status
