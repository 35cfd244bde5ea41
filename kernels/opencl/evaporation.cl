/* erodem OpenCL — evaporation process: evaporation and the wetness running mean of
 * kernels/common/sources.h over the active cells (the CPU loop of kernels/cpu/sources.cpp).
 * The volume lost is summed per work-group into the tally partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "sources.h"

/* One work-item per padded cell (the global size is rounded up to whole work-groups);
 * `evaporate` is 0 when the rate is 0 (then only the wetness runs, as on the CPU). */
__kernel void evaporation(int W, int H, __global const uchar* kind, __global real* depth,
                          __global real* wetness, __global const real* area, real dt, real rate,
                          real tau, int evaporate, __global acc_t* partials, int groups) {
  __local real s[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  const int i = x + y * W;
  real lost = 0;
  if (x >= 1 && y >= 1 && x <= W - 2 && y <= H - 2 && kind[i] == ERODEM_CELL_ACTIVE) {
    if (evaporate) depth[i] = evaporation_cell(depth[i], dt, rate, area[y], &lost);
    wetness[i] = wetness_cell(wetness[i], depth[i], dt, tau);
  }
  cell_group_sum(s, lost, partials + ERODEM_TALLY_EVAPORATED * groups + cell_group_index());
}
