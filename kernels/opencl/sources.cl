/* erodem OpenCL — sources process: rain (kernels/common/sources.h) on the active cells and
 * point/line inflows (the CPU loops of kernels/cpu/sources.cpp). */
#pragma OPENCL FP_CONTRACT OFF
#include "sources.h"

/* One work-item per padded cell of rows 1 .. H - 2 (the host's launch); ghosts keep their
 * depth. factor_pitch: values per row of rain_factor (W, or 0 for one row: param_index). */
__kernel void sources_rain(int W, int H, __global const uchar* restrict kind,
                           __global real* restrict depth, __global const real* restrict rain_factor,
                           int factor_pitch, real dt, real rate) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  rain_sweep_cell(x, y, W, kind, depth, rain_factor, factor_pitch, dt, rate);
}

/* Point and line inflows, one work-item adding them in order (a cell may appear twice):
 * cells are padded indices, amounts the depth each adds (volume / area, rounded on the host
 * as the CPU reference rounds it), and where `with_sediment` the sediment each brings after
 * them (amounts[count + k], m of solid). */
__kernel void sources_points(__global real* restrict depth, __global real* restrict sediment,
                             __global const int* restrict cells,
                             __global const real* restrict amounts, int count, int with_sediment) {
  if (get_global_id(0) != 0) return;
  for (int k = 0; k < count; ++k) depth[cells[k]] += amounts[k];
  if (with_sediment)
    for (int k = 0; k < count; ++k) sediment[cells[k]] += amounts[count + k];
}
