/* erodem OpenCL — evaporation process: evaporation and the wetness running mean of
 * kernels/common/sources.h over the active cells (the CPU loop of kernels/cpu/sources.cpp).
 * The volume lost is summed per work-group into the tally partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "sources.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sum); ghosts keep their values.
 * `evaporate` is 0 when the rate is 0 (then only the wetness runs, as on the CPU). No
 * `restrict` here, unlike the other kernels: PoCL ran this one slower with it (reduce.cl). */
__kernel void evaporation(int W, int H, __global const uchar* kind, __global real* depth,
                          __global real* wetness, __global const real* area, real dt, real rate,
                          real tau, int evaporate, __global acc_t* partials, int stride) {
  __local real s[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  const int i = x + y * W;
  real lost = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
    const real d = depth[i], w = wetness[i];
    real taken;
    const real d_evaporated = evaporation_cell(d, dt, rate, area[y], &taken);
    const real d_new = active & (evaporate != 0) ? d_evaporated : d;
    depth[i] = d_new;
    wetness[i] = active ? wetness_cell(w, d_new, dt, tau) : w;
    lost = active & (evaporate != 0) ? taken : (real)0;
  }
  cell_group_sum(s, lost, partials + ERODEM_TALLY_EVAPORATED * stride + cell_group_index());
}
