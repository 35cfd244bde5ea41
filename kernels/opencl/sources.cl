/* erodem OpenCL — sources process: rain (kernels/common/sources.h) on the active cells and
 * point/line inflows (the CPU loops of kernels/cpu/sources.cpp). */
#pragma OPENCL FP_CONTRACT OFF
#include "sources.h"

/* One work-item per padded cell (the global size may be rounded up). */
__kernel void sources_rain(int W, int H, __global const uchar* kind, __global real* depth,
                           __global const real* rain_factor, real dt, real rate) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x < 1 || y < 1 || x > W - 2 || y > H - 2) return;
  const int i = x + y * W;
  if (kind[i] == ERODEM_CELL_ACTIVE) depth[i] = rain_cell(depth[i], dt, rate, rain_factor[i]);
}

/* Point and line inflows, one work-item adding them in order (a cell may appear twice):
 * cells are padded indices, amounts the depth each adds (volume / area, rounded on the host
 * as the CPU reference rounds it). */
__kernel void sources_points(__global real* depth, __global const int* cells,
                             __global const real* amounts, int count) {
  if (get_global_id(0) != 0) return;
  for (int k = 0; k < count; ++k) depth[cells[k]] += amounts[k];
}
