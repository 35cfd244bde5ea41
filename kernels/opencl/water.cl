/* erodem OpenCL — water process: kernels/common/water.h over the active cells (the CPU loop of
 * kernels/cpu/water.cpp). The per-cell tallies go to two scratch rasters that stats.cl reduces
 * in double; the host swaps the depth buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "water.h"

/* One work-item per padded cell (the global size may be rounded up); every padded cell gets
 * its tallies (0 where nothing runs). */
__kernel void water_update(int W, int H, __global const uchar* kind, __global const real* depth,
                           __global real* depth_out, __global const real* f_left,
                           __global const real* f_right, __global const real* f_top,
                           __global const real* f_bottom, __global const real* dx,
                           __global const real* dy, __global const real* area,
                           __global real* velocity_x, __global real* velocity_y, real dt,
                           real velocity_min_depth, __global real* tally_exchange,
                           __global real* tally_clipped) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x >= W || y >= H) return;
  const int i = x + y * W;
  real exchange = 0, clipped = 0;
  if (x >= 1 && y >= 1 && x <= W - 2 && y <= H - 2 && kind[i] == ERODEM_CELL_ACTIVE)
    water_update_cell(x, y, W, kind, depth, depth_out, f_left, f_right, f_top, f_bottom, dx, dy,
                      area, velocity_x, velocity_y, dt, velocity_min_depth, &exchange, &clipped);
  tally_exchange[i] = exchange;
  tally_clipped[i] = clipped;
}
