/* erodem OpenCL — water process: kernels/common/water.h over the active cells (the CPU loop of
 * kernels/cpu/water.cpp). The volume lifted from rounding-level negatives and the volume the
 * cells gave are summed per work-group into the tally partials (reduce.cl); the exchange through
 * faces with ghosts is summed over the cells beside ghosts only (edges.cl). The host swaps the
 * depth buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "shallow_water.h"
#include "water.h"

/* The water update's tallies of a work-group (water_update, water_erosion): the volume lifted
 * from rounding-level negatives and the volume the cells gave, each summed as cell_group_sum2
 * sums into its slot of partial g (reduce.cl). */
static inline void water_group_sums(__local real* s_clipped, __local real* s_given,
                                    __local acc_t* lanes, real clipped, real given,
                                    __global acc_t* partials, int stride, int g) {
  cell_group_sum2(s_clipped, s_given, lanes, clipped, given,
                  partials + ERODEM_TALLY_CLIPPED * stride + g,
                  partials + ERODEM_TALLY_WATER_EXCHANGED * stride + g);
}

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sums). water_update_cell is
 * branch-free and keeps the ghosts' depth (the first and last column are ghosts; their
 * velocity is 0). */
__kernel void water_update(int W, int H, __global const uchar* restrict kind,
                           __global const real* restrict bed, __global const real* restrict depth,
                           __global real* restrict depth_out, __global const real* restrict f_left,
                           __global const real* restrict f_right,
                           __global const real* restrict f_top,
                           __global const real* restrict f_bottom, __global const real* restrict dx,
                           __global const real* restrict dy, __global const real* restrict area,
                           __global real* restrict velocity_x, __global real* restrict velocity_y,
                           real dt, WaterParams p, __global acc_t* restrict partials, int stride) {
  __local real s_clipped[ERODEM_CELL_GROUP_MAX], s_given[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real exchange, clipped = 0, given = 0; /* exchange: edge_tallies (unused here) */
  if (!ERODEM_PAST_ROW(x, W))
    water_update_cell(x, y, W, kind, bed, depth, depth_out, f_left, f_right, f_top, f_bottom, dx,
                      dy, area, velocity_x, velocity_y, dt, p, &exchange, &clipped, &given);
  water_group_sums(s_clipped, s_given, s_lanes, clipped, given, partials, stride,
                   cell_group_index(stride));
}

/* The shallow-water scheme's cell velocities (the generic sweep "shallow_water_velocity",
 * shallow_water.h) from the unit discharges over the updated depth. */
__kernel void shallow_water_velocity(int W, int H, __global const uchar* restrict kind,
                                     __global const real* restrict depth,
                                     __global const real* restrict q_x,
                                     __global const real* restrict q_y,
                                     __global real* restrict velocity_x,
                                     __global real* restrict velocity_y,
                                     __global const real* restrict area, real dt, WaterParams p,
                                     __global acc_t* restrict partials, int stride) {
  ERODEM_UNTALLIED_CELL(x, y);
  shallow_water_velocity_sweep_cell(x, y, W, kind, depth, q_x, q_y, velocity_x, velocity_y, area,
                                    dt, p);
}
