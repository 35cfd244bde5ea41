/* erodem OpenCL — erosion process: kernels/common/erosion.h over the active cells (the CPU
 * loop of kernels/cpu/erosion.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "erosion.h"

/* Erosion's tallies of a work-group (erosion, erosion_physical and the fused kernels): the
 * eroded and deposited volumes, each summed as cell_group_sum2 sums into its slot of partial g
 * (reduce.cl). */
static inline void erosion_group_sums(__local real* s_eroded, __local real* s_deposited,
                                      __local acc_t* lanes, real eroded, real deposited,
                                      __global acc_t* partials, int stride, int g) {
  cell_group_sum2(s_eroded, s_deposited, lanes, eroded, deposited,
                  partials + ERODEM_TALLY_ERODED * stride + g,
                  partials + ERODEM_TALLY_DEPOSITED * stride + g);
}

/* The physical law's two more (erosion_physical, water_erosion_physical): the bedrock's part
 * of the eroded volume and the bed's bulking, in arrays of their own (their barrier comes
 * after every work-item stored erosion_group_sums' values). */
static inline void bedrock_group_sums(__local real* s_rock, __local real* s_bulking,
                                      __local acc_t* lanes, real rock, real bulking,
                                      __global acc_t* partials, int stride, int g) {
  cell_group_sum2(s_rock, s_bulking, lanes, rock, bulking,
                  partials + ERODEM_TALLY_ERODED_BEDROCK * stride + g,
                  partials + ERODEM_TALLY_BED_BULKING * stride + g);
}

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sums): erosion_sweep_cell. The
 * eroded and deposited volumes are summed per work-group into the tally partials (reduce.cl). */
__kernel void erosion(int W, int H, __global const uchar* restrict kind,
                      __global const real* restrict bed, __global real* restrict bed_out,
                      __global real* restrict bed_residual, __global real* restrict sediment,
                      __global const real* restrict depth, __global const real* restrict velocity_x,
                      __global const real* restrict velocity_y,
                      __global const real* restrict hardness, __global const real* restrict dx,
                      __global const real* restrict dy, __global const real* restrict area, real dt,
                      ErosionParams p, __global acc_t* restrict partials, int stride) {
  __local real s_eroded[ERODEM_CELL_GROUP_MAX], s_deposited[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real eroded = 0, deposited = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    real b;
    erosion_sweep_cell(x, y, W, kind, bed, bed_residual, sediment, depth, velocity_x, velocity_y,
                       hardness, dx, dy, area, dt, p, &b, &eroded, &deposited);
    bed_out[x + y * W] = b;
  }
  erosion_group_sums(s_eroded, s_deposited, s_lanes, eroded, deposited, partials, stride,
                     cell_group_index(stride));
}

/* The physical law (erosion.law = "physical"): sediment_sweep_cell, with the soil thickness and
 * Manning n; the eroded, deposited and bedrock volumes and the bed's bulking are summed per
 * work-group into the tally partials (two cell_group_sum2 on four arrays of their own: the
 * second's barrier comes after every work-item stored the first's values). */
__kernel void erosion_physical(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global real* restrict bed_out, __global real* restrict bed_residual,
    __global real* restrict sediment, __global real* restrict soil,
    __global const real* restrict depth, __global const real* restrict velocity_x,
    __global const real* restrict velocity_y, __global const real* restrict manning,
    __global const real* restrict hardness, __global const real* restrict dx,
    __global const real* restrict dy, __global const real* restrict area, real dt, SedimentParams p,
    __global acc_t* restrict partials, int stride) {
  __local real s_eroded[ERODEM_CELL_GROUP_MAX], s_deposited[ERODEM_CELL_GROUP_MAX],
      s_rock[ERODEM_CELL_GROUP_MAX], s_bulking[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real eroded = 0, deposited = 0, rock = 0, bulking = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    real b;
    sediment_sweep_cell(x, y, W, kind, bed, bed_residual, sediment, soil, depth, velocity_x,
                        velocity_y, manning, hardness, dx, dy, area, dt, p, &b, &eroded, &deposited,
                        &rock, &bulking);
    bed_out[x + y * W] = b;
  }
  const int g = cell_group_index(stride);
  erosion_group_sums(s_eroded, s_deposited, s_lanes, eroded, deposited, partials, stride, g);
  bedrock_group_sums(s_rock, s_bulking, s_lanes, rock, bulking, partials, stride, g);
}
