/* erodem OpenCL — snow process: snowfall, rain on snow, the degree-day melt and the liquid
 * water of kernels/common/snow.h over the active cells (the generic sweep "snow", the CPU loop
 * of kernels/cpu/sweeps.cpp). Its four volumes are summed per work-group into the tally
 * partials (reduce.cl). */
#pragma OPENCL FP_CONTRACT OFF
#include "snow.h"

/* One work-item per padded cell of rows 1 .. H - 2 (where the global size is rounded up,
 * every work-item still reaches the group sums): CELL(x, y, W, kind, TEMPERATURE, ...), its
 * four volumes summed per work-group into the tally slots. The two snow kernels differ only in
 * the cell function and its temperature input (the bed, or the air_temperature field). */
#define ERODEM_SNOW_KERNEL(NAME, CELL, TEMPERATURE)                                           \
  __kernel void NAME(int W, int H, __global const uchar* restrict kind,                       \
                     __global const real* restrict TEMPERATURE,                               \
                     __global const real* restrict rain_factor, __global real* restrict snow, \
                     __global real* restrict liquid, __global real* restrict depth,           \
                     __global const real* restrict area, real dt, SnowParams p,               \
                     __global acc_t* restrict partials, int stride) {                         \
    __local real s_fall[ERODEM_CELL_GROUP_MAX], s_rain[ERODEM_CELL_GROUP_MAX];                \
    __local real s_melt[ERODEM_CELL_GROUP_MAX], s_out[ERODEM_CELL_GROUP_MAX];                 \
    __local acc_t s_lanes[ERODEM_TALLY_LANES];                                                \
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);                           \
    real fall = 0, rain = 0, melted = 0, out = 0;                                             \
    if (!ERODEM_PAST_ROW(x, W))                                                               \
      CELL(x, y, W, kind, TEMPERATURE, rain_factor, snow, liquid, depth, area, dt, p, &fall,  \
           &rain, &melted, &out);                                                             \
    const int g = cell_group_index(stride);                                                   \
    cell_group_sum2(s_fall, s_rain, s_lanes, fall, rain,                                      \
                    partials + ERODEM_TALLY_SNOWFALL * stride + g,                            \
                    partials + ERODEM_TALLY_RAIN_ON_SNOW * stride + g);                       \
    cell_group_sum2(s_melt, s_out, s_lanes, melted, out,                                      \
                    partials + ERODEM_TALLY_SNOW_MELTED * stride + g,                         \
                    partials + ERODEM_TALLY_SNOW_RUNOFF * stride + g);                        \
  }

/* T_ref + lapse (bed - z_ref) (snow_sweep_cell) */
ERODEM_SNOW_KERNEL(snow, snow_sweep_cell, bed)
/* snow.temperature_grids: the cell's air temperature (snow_gridded_sweep_cell) */
ERODEM_SNOW_KERNEL(snow_gridded, snow_gridded_sweep_cell, air_temperature)

/* Sliding (snow.slide_angle): pass 1, what each cell gives per metre of excess drop. */
__kernel void snow_slide_share(int W, int H, __global const uchar* restrict kind,
                               __global const real* restrict bed,
                               __global const real* restrict snow, __global const real* restrict dx,
                               __global const real* restrict dy, __global real* restrict share,
                               __global const real* restrict area, real dt, SnowParams p,
                               __global acc_t* restrict partials, int stride) {
  ERODEM_UNTALLIED_CELL(x, y);
  snow_slide_share_sweep_cell(x, y, W, kind, bed, snow, dx, dy, share, area, dt, p);
}

/* Sliding: pass 2, each pack after what it gave and took. */
__kernel void snow_slide(int W, int H, __global const uchar* restrict kind,
                         __global const real* restrict bed, __global real* restrict snow,
                         __global const real* restrict dx, __global const real* restrict dy,
                         __global const real* restrict share, __global const real* restrict area,
                         real dt, SnowParams p, __global acc_t* restrict partials, int stride) {
  ERODEM_UNTALLIED_CELL(x, y);
  snow_slide_sweep_cell(x, y, W, kind, bed, snow, dx, dy, share, area, dt, p);
}
