/* erodem OpenCL — erosion process: kernels/common/erosion.h over the active cells (the CPU
 * loop of kernels/cpu/erosion.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "erosion.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch). Every work-item
 * computes (in the first and last column on neighbours across the row ends, inside the
 * buffer) and active cells keep the result: no per-work-item branch, so PoCL vectorises it. */
__kernel void erosion(int W, int H, __global const uchar* restrict kind,
                      __global const real* restrict bed, __global real* restrict bed_out,
                      __global real* restrict sediment, __global const real* restrict depth,
                      __global const real* restrict velocity_x,
                      __global const real* restrict velocity_y,
                      __global const real* restrict hardness, __global const real* restrict dx,
                      __global const real* restrict dy, real dt, real capacity_k,
                      real dissolving_rate, real deposition_rate, real min_tilt, real min_depth,
                      real bedrock) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b = bed[i], s = sediment[i];
  real s_new;
  const real b_new = erosion_cell(x, y, W, kind, bed, sediment, depth, velocity_x, velocity_y,
                                  hardness, dx, dy, dt, capacity_k, dissolving_rate,
                                  deposition_rate, min_tilt, min_depth, bedrock, &s_new);
  bed_out[i] = active ? b_new : b;
  sediment[i] = active ? s_new : s;
}
