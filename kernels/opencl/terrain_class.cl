/* erodem OpenCL — terrain classes: the class of every active cell and its class values in the
 * parameter fields, kernels/common/terrain_class.h (the generic sweep "terrain_class", the CPU
 * loop of kernels/cpu/sweeps.cpp). No tallies. */
#pragma OPENCL FP_CONTRACT OFF
#include "terrain_class.h"

/* One work-item per padded cell of rows 1 .. H - 2: terrain_class_sweep_cell. */
__kernel void terrain_class(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict dx, __global const real* restrict dy,
                            __global const real* restrict bed,
                            __global const real* restrict wetness,
                            __global const real* restrict snow, __global real* restrict cls,
                            __global real* restrict manning, __global real* restrict hardness,
                            __global real* restrict ksat, __global real* restrict suction_deficit,
                            __global real* restrict store, __global real* restrict talus,
                            __global const real* restrict area, real dt, TerrainClassParams p,
                            __global acc_t* restrict partials, int stride) {
  ERODEM_UNTALLIED_CELL(x, y);
  terrain_class_sweep_cell(x, y, W, kind, dx, dy, bed, wetness, snow, cls, manning, hardness, ksat,
                           suction_deficit, store, talus, area, dt, p);
}
