#!/usr/bin/env bash
# erodem — N = 1, 2 strong and weak scaling of `mpirun -np N erodem run` (docs/mpi.md,
# "Scaling on this machine"), in alternating rounds (these machines drift between runs).
# A synthetic valley, local inertial + erosion + thermal + 100 mm/h rain, 50 adaptive steps,
# float32, no restart state; prints the `ran ... wall` line of each run:
#   2048^2 N=1 one thread | 2048^2 N=2 one thread each | 2048^2 N=1 two threads | 1448^2 N=1
# (1448^2 is the cells of one rank of the 2048^2 run: weak scaling).
# BACKEND `opencl` runs the same on the OpenCL backend, PoCL's threads counted instead
# (POCL_MAX_PTHREAD_COUNT: each rank its own context and threads).
# Usage: mpi_scaling.sh path/to/erodem [ROUNDS] [BACKEND]   (default 3, cpu)
set -euo pipefail
erodem=$(realpath "$1")
rounds=${2:-3}
backend=${3:-cpu}
threads=OMP_NUM_THREADS
if [ "$backend" = opencl ]; then threads=POCL_MAX_PTHREAD_COUNT; fi
export OMP_NUM_THREADS=1 POCL_MAX_PTHREAD_COUNT=2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cat >base.toml <<TOML
[dem]
synthetic = "valley"
size = 2048
seed = 7
relief = "150 m"
cell_size = "10 m"

[initial]
water_depth = "5 mm"

[time]
steps = 50
adaptive = true
cfl = 0.7
dt_max = "1 s"

[flow]
scheme = "local_inertial"

[rain]
rate = "100 mm/h"

[erosion]
enabled = true

[thermal]
enabled = true
talus_angle = 30.0

[output]
every = 1000
restart_state = false
TOML
mpi=(mpirun --allow-run-as-root --oversubscribe --bind-to none -x OMP_NUM_THREADS -x OMP_WAIT_POLICY
  -x POCL_MAX_PTHREAD_COUNT)
export OMP_WAIT_POLICY=PASSIVE
run() {
  local label=$1
  shift
  echo "$backend $label | $("$@" --backend "$backend" --output out.h5 --overwrite 2>/dev/null | grep '^ran')"
}
# with THREADS LABEL COMMAND...: run with THREADS threads a process (OpenMP's or PoCL's)
with() {
  local n=$1
  shift
  (
    export "$threads=$n"
    run "$@"
  )
}
for _ in $(seq "$rounds"); do
  with 1 "2048^2 N=1 t=1" "$erodem" run base.toml
  with 1 "2048^2 N=2 t=1" "${mpi[@]}" -np 2 "$erodem" run base.toml
  with 2 "2048^2 N=1 t=2" "$erodem" run base.toml
  with 1 "1448^2 N=1 t=1" "$erodem" run base.toml --set dem.size=1448
done
