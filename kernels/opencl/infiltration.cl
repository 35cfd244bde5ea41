/* erodem OpenCL — infiltration process: Green-Ampt of kernels/common/infiltration.h over the
 * active cells (the generic sweep "infiltration", the CPU loop of kernels/cpu/sweeps.cpp). The
 * volumes infiltrated and drained are summed per work-group into the tally partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "infiltration.h"

/* One work-item per padded cell of rows 1 .. H - 2 (where the global size is rounded up,
 * every work-item still reaches the group sums): infiltration_sweep_cell. */
__kernel void infiltration(int W, int H, __global const uchar* restrict kind,
                           __global real* restrict depth, __global real* restrict infiltrated,
                           __global const real* restrict ksat,
                           __global const real* restrict suction,
                           __global const real* restrict store, __global const real* restrict area,
                           real dt, InfiltrationParams p, __global acc_t* restrict partials,
                           int stride) {
  __local real s_in[ERODEM_CELL_GROUP_MAX], s_drained[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real taken = 0, drained = 0;
  if (!ERODEM_PAST_ROW(x, W))
    infiltration_sweep_cell(x, y, W, kind, depth, infiltrated, ksat, suction, store, area, dt, p,
                            &taken, &drained);
  const int g = cell_group_index(stride);
  cell_group_sum2(s_in, s_drained, s_lanes, taken, drained,
                  partials + ERODEM_TALLY_INFILTRATED * stride + g,
                  partials + ERODEM_TALLY_SOIL_DRAINED * stride + g);
}
