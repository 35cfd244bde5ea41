/* erodem OpenCL — thermal process: the two passes of kernels/common/thermal.h (the CPU loops
 * of kernels/cpu/thermal.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "thermal.h"

/* Pass 1, one work-item per padded cell of rows 1 .. H - 2 (the host's launch); 0 for
 * ghosts. Branch-free over the row (see erosion.cl). */
__kernel void thermal_share(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict bed, __global const real* restrict dx,
                            __global const real* restrict dy, __global const real* restrict area,
                            __global real* restrict share, real dt, real rate, real tan_talus) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  const int i = x + y * W;
  const real s = thermal_share_cell(x, y, W, kind, bed, dx, dy, area, dt, rate, tan_talus);
  share[i] = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE) ? s : (real)0;
}

/* Pass 2, one work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the
 * global size is rounded up, every work-item still reaches the group sum); ghosts keep their
 * bed. The residual is read and written at the work-item's own cell only. The volume the
 * cells gave is summed per work-group into the tally partials (reduce.cl). */
__kernel void thermal_apply(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict bed, __global real* restrict bed_residual,
                            __global const real* restrict share, __global const real* restrict dx,
                            __global const real* restrict dy, __global const real* restrict area,
                            __global real* restrict bed_out, real tan_talus,
                            __global acc_t* restrict partials, int stride) {
  __local real s_sum[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real moved = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    const int i = x + y * W;
    const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
    const real lo = bed_residual[i];
    real lo_new, gave;
    const real b = thermal_apply_cell(x, y, W, kind, bed, bed_residual, share, dx, dy, area,
                                      tan_talus, &lo_new, &gave);
    bed_out[i] = active ? b : bed[i];
    bed_residual[i] = active ? lo_new : lo;
    moved = active ? gave : (real)0;
  }
  cell_group_sum(s_sum, moved, partials + ERODEM_TALLY_THERMAL * stride + cell_group_index());
}
