/* erodem OpenCL — thermal process: the two passes of kernels/common/thermal.h (the CPU loops
 * of kernels/cpu/thermal.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "thermal.h"

/* Pass 1, one work-item per padded cell (the global size may be rounded up). */
__kernel void thermal_share(int W, int H, __global const uchar* kind, __global const real* bed,
                            __global const real* dx, __global const real* dy,
                            __global const real* area, __global real* share, real dt, real rate,
                            real tan_talus) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x < 1 || y < 1 || x > W - 2 || y > H - 2) return;
  const int i = x + y * W;
  share[i] = kind[i] == ERODEM_CELL_ACTIVE
                 ? thermal_share_cell(x, y, W, kind, bed, dx, dy, area, dt, rate, tan_talus)
                 : (real)0;
}

/* Pass 2, one work-item per padded cell (the global size may be rounded up). */
__kernel void thermal_apply(int W, int H, __global const uchar* kind, __global const real* bed,
                            __global const real* share, __global const real* dx,
                            __global const real* dy, __global const real* area,
                            __global real* bed_out, real tan_talus) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x < 1 || y < 1 || x > W - 2 || y > H - 2) return;
  const int i = x + y * W;
  bed_out[i] = kind[i] == ERODEM_CELL_ACTIVE
                   ? thermal_apply_cell(x, y, W, kind, bed, share, dx, dy, area, tan_talus)
                   : bed[i];
}
