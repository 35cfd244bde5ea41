/* erodem OpenCL — transport process: kernels/common/transport.h over the active cells (the
 * CPU loops of kernels/cpu/transport.cpp); the host swaps the sediment buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "transport.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sum); ghosts keep their sediment.
 * The sediment carried out of the domain is summed over the cells beside ghosts only
 * (edges.cl); the sediment the cells gave per work-group into the tally partials. */
__kernel void transport_conservative(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict sediment,
    __global real* restrict sediment_out, __global const real* restrict depth_flow,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global const real* restrict area, real dt, __global acc_t* restrict partials, int stride) {
  __local real s_sum[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real given = 0;
  real carried; /* edge_tallies sums it over the cells beside ghosts (unused here) */
  if (!ERODEM_PAST_ROW(x, W)) {
    real s;
    transport_conservative_sweep_cell(x, y, W, kind, sediment, depth_flow, f_left, f_right, f_top,
                                      f_bottom, area, dt, &s, &carried, &given);
    sediment_out[x + y * W] = s;
  }
  cell_group_sum(s_sum, s_lanes, given,
                 partials + ERODEM_TALLY_SEDIMENT_EXCHANGED * stride + cell_group_index(stride));
}

/* The change of sum(s * area) is reduced afterwards by reduce_change (stats.cl). */
__kernel void transport_semi_lagrangian(int W, int H, __global const uchar* restrict kind,
                                        __global const real* restrict sediment,
                                        __global real* restrict sediment_out,
                                        __global const real* restrict velocity_x,
                                        __global const real* restrict velocity_y,
                                        __global const real* restrict dx,
                                        __global const real* restrict dy, real dt, int periodic_x) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  const int i = x + y * W;
  const real s_new = transport_semi_lagrangian_cell(x, y, W, H, sediment, velocity_x, velocity_y,
                                                    dx, dy, dt, periodic_x);
  sediment_out[i] = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE) ? s_new : sediment[i];
}
