/* erodem OpenCL — evaporation process: evaporation and the wetness running mean of
 * kernels/common/sources.h over the active cells (the CPU loop of kernels/cpu/sources.cpp).
 * The volume lost is summed per work-group into the tally partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "sources.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sum): evaporation_sweep_cell. No
 * `restrict` here, unlike the other kernels: PoCL ran this one slower with it (reduce.cl). */
__kernel void evaporation(int W, int H, __global const uchar* kind, __global real* depth,
                          __global real* wetness, __global const real* area, real dt,
                          EvaporationParams p, __global acc_t* partials, int stride) {
  __local real s[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real lost = 0;
  if (!ERODEM_PAST_ROW(x, W))
    evaporation_sweep_cell(x, y, W, kind, depth, wetness, area, dt, p, &lost);
  cell_group_sum(s, s_lanes, lost,
                 partials + ERODEM_TALLY_EVAPORATED * stride + cell_group_index(stride));
}
