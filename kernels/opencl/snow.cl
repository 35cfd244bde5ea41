/* erodem OpenCL — snow process: the degree-day melt of kernels/common/snow.h over the active
 * cells (the generic sweep "snow", the CPU loop of kernels/cpu/sweeps.cpp). The volume melted
 * is summed per work-group into the tally partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "snow.h"

/* One work-item per padded cell of rows 1 .. H - 2 (where the global size is rounded up,
 * every work-item still reaches the group sum): snow_sweep_cell. */
__kernel void snow(int W, int H, __global const uchar* restrict kind,
                   __global const real* restrict bed, __global real* restrict snow,
                   __global real* restrict depth, __global const real* restrict area, real dt,
                   SnowParams p, __global acc_t* restrict partials, int stride) {
  __local real s[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real melted = 0;
  if (!ERODEM_PAST_ROW(x, W))
    snow_sweep_cell(x, y, W, kind, bed, snow, depth, area, dt, p, &melted);
  cell_group_sum(s, melted, partials + ERODEM_TALLY_SNOW_MELTED * stride + cell_group_index());
}
