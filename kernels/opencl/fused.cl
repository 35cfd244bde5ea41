/* erodem OpenCL — fused passes (Backend::fused_parts): the water update and erosion in one
 * kernel. Each work-item updates its cell's water (water_update_cell, as water_update) and then
 * erodes it (erosion_sweep_cell or sediment_sweep_cell, as erosion and erosion_physical). Erosion
 * reads only its own cell of what the water update writes (the new depth and the velocities),
 * and the neighbours' bed, which the water update does not change, so no work-item waits for
 * another between the two: the kernels' per-cell functions on the same numbers, the same bits
 * as the two kernels one after the other (tests/test_fused.cpp). What the fusion saves is the
 * second sweep's reads of the kind, the bed, the depth and both velocities (17 B per cell) and
 * one launch. The tallies go to the slots of the two kernels' partials, summed per work-group
 * as each sums them (water_group_sums, erosion_group_sums, bedrock_group_sums), each pair in
 * arrays of its own (a pair's barrier comes after every work-item stored the pair before it).
 * The host swaps the depth and the bed buffers after it. */
#pragma OPENCL FP_CONTRACT OFF
#include "erosion.h"
#include "water.h"

/* Mei's law: the arguments of water_update, then those of erosion that it does not share
 * (bed_out, bed_residual, sediment, hardness, ErosionParams). */
__kernel void water_erosion(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict bed, __global const real* restrict depth,
                            __global real* restrict depth_out, __global const real* restrict f_left,
                            __global const real* restrict f_right,
                            __global const real* restrict f_top,
                            __global const real* restrict f_bottom,
                            __global const real* restrict dx, __global const real* restrict dy,
                            __global const real* restrict area, __global real* restrict velocity_x,
                            __global real* restrict velocity_y, real dt, WaterParams wp,
                            __global real* restrict bed_out, __global real* restrict bed_residual,
                            __global real* restrict sediment,
                            __global const real* restrict hardness, ErosionParams ep,
                            __global acc_t* restrict partials, int stride) {
  __local real s_clipped[ERODEM_CELL_GROUP_MAX], s_given[ERODEM_CELL_GROUP_MAX];
  __local real s_eroded[ERODEM_CELL_GROUP_MAX], s_deposited[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real exchange, clipped = 0, given = 0, eroded = 0, deposited = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    water_update_cell(x, y, W, kind, bed, depth, depth_out, f_left, f_right, f_top, f_bottom, dx,
                      dy, area, velocity_x, velocity_y, dt, wp, &exchange, &clipped, &given);
    real b;
    erosion_sweep_cell(x, y, W, kind, bed, bed_residual, sediment, depth_out, velocity_x,
                       velocity_y, hardness, dx, dy, area, dt, ep, &b, &eroded, &deposited);
    bed_out[x + y * W] = b;
  }
  const int g = cell_group_index(stride);
  water_group_sums(s_clipped, s_given, s_lanes, clipped, given, partials, stride, g);
  erosion_group_sums(s_eroded, s_deposited, s_lanes, eroded, deposited, partials, stride, g);
}

/* The physical law: the arguments of water_update, then those of erosion_physical that it
 * does not share. */
__kernel void water_erosion_physical(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global real* restrict depth_out,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict area, __global real* restrict velocity_x,
    __global real* restrict velocity_y, real dt, WaterParams wp, __global real* restrict bed_out,
    __global real* restrict bed_residual, __global real* restrict sediment,
    __global real* restrict soil, __global const real* restrict manning,
    __global const real* restrict hardness, SedimentParams sp, __global acc_t* restrict partials,
    int stride) {
  __local real s_clipped[ERODEM_CELL_GROUP_MAX], s_given[ERODEM_CELL_GROUP_MAX];
  __local real s_eroded[ERODEM_CELL_GROUP_MAX], s_deposited[ERODEM_CELL_GROUP_MAX],
      s_rock[ERODEM_CELL_GROUP_MAX], s_bulking[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real exchange, clipped = 0, given = 0, eroded = 0, deposited = 0, rock = 0, bulking = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    water_update_cell(x, y, W, kind, bed, depth, depth_out, f_left, f_right, f_top, f_bottom, dx,
                      dy, area, velocity_x, velocity_y, dt, wp, &exchange, &clipped, &given);
    real b;
    sediment_sweep_cell(x, y, W, kind, bed, bed_residual, sediment, soil, depth_out, velocity_x,
                        velocity_y, manning, hardness, dx, dy, area, dt, sp, &b, &eroded,
                        &deposited, &rock, &bulking);
    bed_out[x + y * W] = b;
  }
  const int g = cell_group_index(stride);
  water_group_sums(s_clipped, s_given, s_lanes, clipped, given, partials, stride, g);
  erosion_group_sums(s_eroded, s_deposited, s_lanes, eroded, deposited, partials, stride, g);
  bedrock_group_sums(s_rock, s_bulking, s_lanes, rock, bulking, partials, stride, g);
}
