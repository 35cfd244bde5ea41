/* erodem OpenCL — flow process: kernels/common/flow.h over every padded cell (ghosts give
 * water too), as the CPU loop of kernels/cpu/flow.cpp; the host swaps the flux buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "flow.h"

/* One work-item per padded cell (the global size may be rounded up). */
__kernel void flow_pipes(int W, int H, __global const uchar* kind, __global const real* bed,
                         __global const real* depth, __global const real* dx,
                         __global const real* dy, __global const real* area,
                         __global const real* f_left, __global const real* f_right,
                         __global const real* f_top, __global const real* f_bottom,
                         __global real* out_left, __global real* out_right, __global real* out_top,
                         __global real* out_bottom, real dt, real gravity, real pipe_area,
                         real pipe_length) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x >= W || y >= H) return;
  flow_pipes_cell(x, y, W, H, kind, bed, depth, dx, dy, area, f_left, f_right, f_top, f_bottom,
                  out_left, out_right, out_top, out_bottom, dt, gravity, pipe_area, pipe_length);
}

__kernel void flow_local_inertial(int W, int H, __global const uchar* kind,
                                  __global const real* bed, __global const real* depth,
                                  __global const real* manning, __global const real* dx,
                                  __global const real* dy, __global const real* area,
                                  __global const real* f_left, __global const real* f_right,
                                  __global const real* f_top, __global const real* f_bottom,
                                  __global real* out_left, __global real* out_right,
                                  __global real* out_top, __global real* out_bottom, real dt,
                                  real gravity, real theta, real dry_depth) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (x >= W || y >= H) return;
  flow_local_inertial_cell(x, y, W, H, kind, bed, depth, manning, dx, dy, area, f_left, f_right,
                           f_top, f_bottom, out_left, out_right, out_top, out_bottom, dt, gravity,
                           theta, dry_depth);
}
