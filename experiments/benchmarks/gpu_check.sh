#!/usr/bin/env bash
# erodem — the checks a machine with an OpenCL GPU runs (docs/performance.md, "On a GPU"):
#  1. `erodem devices`: the GPU must be listed (exit 77 otherwise: nothing here would run on it);
#  2. `erodem bench` of the default erosion step at 4096^2 on the GPU beside the CPU reference
#     (all cores), water only at 1024^2 (local inertial and pipes, the Landlab scenario of
#     landlab_compare.py) and the shallow-water scheme at 4096^2 on the GPU (the OpenCL backend
#     runs float32 only); each with its memory peak (host
#     VmHWM and the device buffers);
#  3. the OpenCL tests of the gtest suite on the GPU (the agreement with the CPU reference, every
#     validation case on the opencl_float32 target, restart, sections, periodic, the bench's
#     device-memory probe), in SHARDS processes side by side, the validation figures they
#     measure recorded in OUT/validation (GPU_CHECK_TEST_LIMIT: seconds, default 420).
# Each step's output goes to OUT/<step>.txt as well as the terminal; a step that fails is
# reported and the next one runs. Exit status: the number of failed steps (0: all passed).
#
# Usage: bash experiments/benchmarks/gpu_check.sh [BUILD_DIR [OUT [SHARDS]]]
#   (defaults: build, build/gpu_check, 4). ERODEM_OPENCL_DEVICE selects another device.
# On a GPU machine without erodem's packages, gpu_bundle.sh carries the binaries and libraries.
set -uo pipefail
cd "$(dirname "$0")/../.."
B=${1:-build}
OUT=${2:-$B/gpu_check}
SHARDS=${3:-4}
erodem=$B/cli/erodem
tests=$B/tests/erodem_tests
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/$B/pocl-cache}
mkdir -p "$POCL_CACHE_DIR"
failed=0
step() {  # step NAME TIMEOUT_S COMMAND...: runs COMMAND, output to OUT/NAME.txt
  local name=$1 limit=$2
  shift 2
  echo "== $(date -u +%T) $name: $*"
  local t0=$SECONDS
  if [ "$(type -t "$1")" = function ]; then
    LIMIT=$limit "$@" > "$OUT/$name.txt" 2>&1
  else
    timeout "$limit" "$@" > "$OUT/$name.txt" 2>&1
  fi
  local rc=$?
  cat "$OUT/$name.txt"
  echo "== $name: exit $rc in $((SECONDS - t0)) s"
  ((rc == 0)) || failed=$((failed + 1))
  return $rc
}

step devices 60 "$erodem" devices || exit 77
[ -n "${GPU_CHECK_ANY_DEVICE:-}" ] || grep -qE "^ +GPU, [0-9]+ compute units" "$OUT/devices.txt" ||
  { echo "gpu_check: no OpenCL GPU listed (GPU_CHECK_ANY_DEVICE=1 runs on any device)"; exit 77; }

# The kernels must build for the device: a few steps of every process, else nothing else runs.
step kernels 120 "$erodem" bench --size 64 --steps 1 --backends opencl --stream-floats 1048576 ||
  { echo "gpu_check: the OpenCL kernels do not run on this device"; exit 1; }

# 2. The bench (GPU_CHECK_TESTS_ONLY=1 skips it). The default step (local inertial, erosion,
# thermal, float32) at 4096^2.
[ -n "${GPU_CHECK_TESTS_ONLY:-}" ] || {
  step bench_4096 300 "$erodem" bench --size 4096 --steps 10 --backends cpu,opencl --threads 0
  water_only=(--set erosion.enabled=false --set thermal.enabled=false --set evaporation.rate=0
    --set flow.manning_n=0.03)
  step bench_1024_water 200 "$erodem" bench --size 1024 --steps 50 --backends cpu,opencl \
    --threads 0 "${water_only[@]}"
  step bench_1024_water_pipes 200 "$erodem" bench --size 1024 --steps 50 --backends cpu,opencl \
    --threads 0 "${water_only[@]}" --set flow.scheme=pipes
  step bench_4096_shallow_water 300 "$erodem" bench --size 4096 --steps 10 --backends opencl \
    --set flow.scheme=shallow_water
}
# 3. The OpenCL tests, sharded over SHARDS processes (the CPU reference sides share the cores).
filter='OpenCl/*:*OpenCl*:*Agreement*:*opencl*:ErodibilityNoise.*:CliTools.Bench*'
filter+=':CliTools.Devices*:AutoBackend.*:OpenClCopyBandwidth.*'
# The validation figures the tests measure on the GPU go to OUT/validation (as the report's).
run_shards() {
  local pids=() rc=0
  mkdir -p "$OUT/validation/profiles"
  for ((i = 0; i < SHARDS; ++i)); do
    ERODEM_VALIDATION_DIR=$OUT/validation GTEST_TOTAL_SHARDS=$SHARDS GTEST_SHARD_INDEX=$i \
      OMP_NUM_THREADS=$(($(nproc) / SHARDS)) timeout "$LIMIT" \
      "$tests" --gtest_filter="$filter" --gtest_brief=1 > "$OUT/tests_shard$i.log" 2>&1 &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || rc=1; done
  for ((i = 0; i < SHARDS; ++i)); do
    grep -E "^\[( +OK|  FAILED|  PASSED|  SKIPPED) |tests ran|^\[(opencl copy|bench on|agreement)" \
      "$OUT/tests_shard$i.log" | grep -v "^\[       OK" || true
    grep -E "^\[  FAILED" -B30 "$OUT/tests_shard$i.log" | head -80 || true
  done
  return $rc
}
step tests ${GPU_CHECK_TEST_LIMIT:-420} run_shards

echo "gpu_check: $failed step(s) failed"
exit $failed
