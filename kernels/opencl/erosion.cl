/* erodem OpenCL — erosion process: kernels/common/erosion.h over the active cells (the CPU
 * loop of kernels/cpu/erosion.cpp); the host swaps the bed buffers. */
#pragma OPENCL FP_CONTRACT OFF
#include "erosion.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch; where the global size
 * is rounded up, every work-item still reaches the group sums). Every work-item of the row
 * computes (in the first and last column on neighbours across the row ends, inside the
 * buffer) and active cells keep the result: no per-work-item branch, so PoCL vectorises it.
 * The residual is read and written at the work-item's own cell only. The eroded and deposited
 * volumes are summed per work-group into the tally partials (reduce.cl). */
__kernel void erosion(int W, int H, __global const uchar* restrict kind,
                      __global const real* restrict bed, __global real* restrict bed_out,
                      __global real* restrict bed_residual, __global real* restrict sediment,
                      __global const real* restrict depth, __global const real* restrict velocity_x,
                      __global const real* restrict velocity_y,
                      __global const real* restrict hardness, __global const real* restrict dx,
                      __global const real* restrict dy, __global const real* restrict area, real dt,
                      real capacity_k, real dissolving_rate, real deposition_rate, real min_tilt,
                      real min_depth, real bedrock, __global acc_t* restrict partials, int stride) {
  __local real s_eroded[ERODEM_CELL_GROUP_MAX], s_deposited[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  real eroded = 0, deposited = 0;
  if (!ERODEM_PAST_ROW(x, W)) {
    const int i = x + y * W;
    const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
    /* unconditional loads (the row's area too: under `active` PoCL made it a gather and left
     * the kernel scalar) */
    const real b = bed[i], lo = bed_residual[i], s = sediment[i], cell_area = area[y];
    real lo_new, s_new, moved;
    const real b_new =
        erosion_cell(x, y, W, kind, bed, bed_residual, sediment, depth, velocity_x, velocity_y,
                     hardness, dx, dy, dt, capacity_k, dissolving_rate, deposition_rate, min_tilt,
                     min_depth, bedrock, &lo_new, &s_new, &moved);
    bed_out[i] = active ? b_new : b;
    bed_residual[i] = active ? lo_new : lo;
    sediment[i] = active ? s_new : s;
    const real volume = moved * cell_area;
    eroded = active & (volume > 0) ? volume : (real)0;
    deposited = active & (volume < 0) ? -volume : (real)0;
  }
  const int g = cell_group_index();
  cell_group_sum2(s_eroded, s_deposited, eroded, deposited,
                  partials + ERODEM_TALLY_ERODED * stride + g,
                  partials + ERODEM_TALLY_DEPOSITED * stride + g);
}
