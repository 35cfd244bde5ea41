/* erodem OpenCL — thermal process: the two passes of kernels/common/thermal.h (the CPU loops
 * of kernels/cpu/thermal.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "thermal.h"

/* Pass 1, one work-item per padded cell of rows 1 .. H - 2 (the host's launch):
 * thermal_share_sweep_cell. */
__kernel void thermal_share(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict bed,
                            __global const real* restrict wetness,
                            __global const real* restrict talus, __global const real* restrict dx,
                            __global const real* restrict dy, __global const real* restrict area,
                            __global real* restrict share, real dt, ThermalParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  thermal_share_sweep_cell(x, y, W, kind, bed, wetness, talus, dx, dy, area, share, dt, p);
}

/* Pass 2, one work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the
 * global size is rounded up, every work-item still reaches the group sum):
 * thermal_apply_sweep_cell. The volume the cells gave is summed per work-group into the tally
 * partials (reduce.cl). */
__kernel void thermal_apply(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict bed, __global real* restrict bed_residual,
                            __global const real* restrict wetness,
                            __global const real* restrict talus,
                            __global const real* restrict share, __global const real* restrict dx,
                            __global const real* restrict dy, __global const real* restrict area,
                            __global real* restrict bed_out, ThermalParams p,
                            __global acc_t* restrict partials, int stride) {
  __local real s_sum[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real moved = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    real b;
    thermal_apply_sweep_cell(x, y, W, kind, bed, bed_residual, wetness, talus, share, dx, dy, area,
                             p, &b, &moved);
    bed_out[x + y * W] = b;
  }
  cell_group_sum(s_sum, s_lanes, moved,
                 partials + ERODEM_TALLY_THERMAL_MOVED * stride + cell_group_index(stride));
}
