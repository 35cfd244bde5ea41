/* erodem OpenCL — erosion process: kernels/common/erosion.h over the active cells (the CPU
 * loop of kernels/cpu/erosion.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "erosion.h"

/* One work-item per padded cell (the global size may be rounded up). */
__kernel void erosion(int W, int H, __global const uchar* kind, __global const real* bed,
                      __global real* bed_out, __global real* sediment, __global const real* depth,
                      __global const real* velocity_x, __global const real* velocity_y,
                      __global const real* hardness, __global const real* dx,
                      __global const real* dy, real dt, real capacity_k, real dissolving_rate,
                      real deposition_rate, real min_tilt, real min_depth, real bedrock) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x < 1 || y < 1 || x > W - 2 || y > H - 2) return;
  /* PoCL does not vectorise this kernel (the bed tilt stops it), so inactive cells return
   * early rather than compute and discard */
  const int i = x + y * W;
  if (kind[i] != ERODEM_CELL_ACTIVE) return;
  real s_new;
  bed_out[i] = erosion_cell(x, y, W, kind, bed, sediment, depth, velocity_x, velocity_y, hardness,
                            dx, dy, dt, capacity_k, dissolving_rate, deposition_rate, min_tilt,
                            min_depth, bedrock, &s_new);
  sediment[i] = s_new;
}
