/* erodem — the snow pack (MODEL.md step 8): snow water equivalent and the liquid water it
 * holds; precipitation below a temperature threshold falls on it as snow; it melts by a
 * degree-day rule (Hock 2003) with an elevation lapse rate, plus the heat the rain brings; the
 * melt and the rain on the pack are held up to a retention fraction of the pack, the rest
 * reaches the water depth; on slopes steeper than a slide angle the pack slides downhill. */
#ifndef ERODEM_KERNELS_COMMON_SNOW_H
#define ERODEM_KERNELS_COMMON_SNOW_H

#include "compat.h"
/* talus_excess, talus_excess_out: sliding measures the excess drop as slope collapse does */
#include "thermal.h"

/* The constants of the snow pack (snow_params, kernels/cell_params.hpp); air_temperature and
 * rain_rate follow the step (step_cell_params: the series' values at the step midpoint). */
ERODEM_PARAMS_BEGIN(SnowParams)
  real melt_factor;          /* DDF, melt per kelvin above melt_temperature (m/s per K) */
  real melt_temperature;     /* T_melt (degrees C) */
  real air_temperature;      /* T_ref(t) at reference_elevation (degrees C), per step */
  real reference_elevation;  /* z_ref (m) */
  real lapse_rate;           /* dT/dz (K/m) */
  real snowfall_temperature; /* precipitation falls as snow below this (degrees C) */
  real retention;            /* liquid water the pack holds per unit of its SWE (1) */
  real rain_heat;            /* c_w / L_f: melt per m of rain per kelvin (1/K) */
  real rain_rate;            /* the step's rain rate (m/s; times the cell's rain factor) */
  real tan_slide;            /* tan of snow.slide_angle (1) */
  real slide_rate;           /* fraction of a sliding pack that moves per second (1/s) */
  int rain_factor_pitch;     /* values per row of the rain factor array (param_index, compat.h) */
ERODEM_PARAMS_END(SnowParams)

ERODEM_BEGIN_NAMESPACE

/* The air temperature at elevation z (m): T_ref + lapse_rate (z - z_ref) (degrees C). */
ERODEM_FN real snow_air_temperature(real z, ERODEM_P(SnowParams) p) {
  return p.air_temperature + p.lapse_rate * (z - p.reference_elevation);
}

/* The melt of one cell in dt (s) at air temperature T (degrees C): DDF max(0, T - T_melt) dt
 * plus the heat of the rain `rain` (m of water) on the pack, rain c_w max(0, T) / L_f; never
 * more than the pack `snow` (m of water equivalent). */
ERODEM_FN real snow_melt_cell(real snow, real T, real rain, real dt, ERODEM_P(SnowParams) p) {
  const real excess = T - p.melt_temperature;
  const real degree_day = p.melt_factor * (excess > (real)0 ? excess : (real)0) * dt;
  const real potential = degree_day + rain * p.rain_heat * (T > (real)0 ? T : (real)0);
  return potential < snow ? potential : snow;
}

/* The snow pack of padded cell i (`active`: inside the grid and of kind active) at air
 * temperature T (degrees C), the body of the snow sweeps (snow_sweep_cell,
 * snow_gridded_sweep_cell):
 *   P = min(rain_rate rain_factor dt, d): the step's rain, which the sources put on the depth;
 *   below snowfall_temperature it falls as snow: the pack takes P back from the depth
 *   (*snowfall); above, on a pack (snow > 0) it is rain on snow: the pack's liquid water takes
 *   it back (*rain_on_snow) and it melts rain c_w max(0, T) / L_f more;
 *   the melt M (snow_melt_cell) turns pack into liquid water (*melted);
 *   the liquid water above retention times the pack that is left reaches the depth (*runoff).
 * Others keep everything. Volumes in m^3 (0 for others); `a` is the cell's area, f its rain
 * factor. Branch-free. */
ERODEM_FN void snow_pack_cell(int i, int active, real T, real f, GLOBAL real* snow,
                              GLOBAL real* liquid, GLOBAL real* depth, real a, real dt,
                              ERODEM_P(SnowParams) p, real* snowfall, real* rain_on_snow,
                              real* melted, real* runoff) {
  /* unconditional loads: if-convertible */
  const real s = snow[i], l = liquid[i], d = depth[i];
  const real rained = dt * p.rain_rate * f; /* as rain_cell (sources.h) computed it */
  const real P = active ? (rained < d ? rained : d) : (real)0;
  const int snows = T < p.snowfall_temperature;
  const real fall = snows ? P : (real)0;
  const real on_pack = (!snows & (s > (real)0)) ? P : (real)0;
  const real pack = s + fall;
  const real m = active ? snow_melt_cell(pack, T, on_pack, dt, p) : (real)0;
  const real s_new = pack - m;
  const real held = l + m + on_pack;
  const real capacity = p.retention * s_new;
  const real out = held > capacity ? held - capacity : (real)0;
  snow[i] = s_new;
  liquid[i] = held - out;
  depth[i] = d - fall - on_pack + out;
  *snowfall = fall * a;
  *rain_on_snow = on_pack * a;
  *melted = m * a;
  *runoff = out * a;
}

/* The snow sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both backends'
 * loops (the generic sweep "snow": kernels/cpu/sweeps.cpp, kernels/opencl/snow.cl): the pack
 * (snow_pack_cell) of an active cell (1 <= x <= W - 2, kind active) at
 * T = snow_air_temperature(bed). */
ERODEM_FN void snow_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                               GLOBAL const real* bed, GLOBAL const real* rain_factor,
                               GLOBAL real* snow, GLOBAL real* liquid, GLOBAL real* depth,
                               GLOBAL const real* area, real dt, ERODEM_P(SnowParams) p,
                               real* snowfall, real* rain_on_snow, real* melted, real* runoff) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  snow_pack_cell(i, active, snow_air_temperature(bed[i], p),
                 rain_factor[param_index(x, y, p.rain_factor_pitch)], snow, liquid, depth, area[y],
                 dt, p, snowfall, rain_on_snow, melted, runoff);
}

/* The snow sweep with snow.temperature_grids (the generic sweep "snow_gridded"): as
 * snow_sweep_cell at the cell's own air temperature T = air_temperature[i] (degrees C; the
 * bands interpolated to the step's midpoint by the host), with no lapse correction. */
ERODEM_FN void snow_gridded_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                       GLOBAL const real* air_temperature,
                                       GLOBAL const real* rain_factor, GLOBAL real* snow,
                                       GLOBAL real* liquid, GLOBAL real* depth,
                                       GLOBAL const real* area, real dt, ERODEM_P(SnowParams) p,
                                       real* snowfall, real* rain_on_snow, real* melted,
                                       real* runoff) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  snow_pack_cell(i, active, air_temperature[i], rain_factor[param_index(x, y, p.rain_factor_pitch)],
                 snow, liquid, depth, area[y], dt, p, snowfall, rain_on_snow, melted, runoff);
}

/* Sliding, pass 1 (the generic sweep "snow_slide_share"), padded cell (x, y) of a row
 * 1 <= y <= H - 2: an active cell gives min(1, slide_rate dt) of its pack to its active
 * neighbours lower than the slide angle below it, in proportion to their excess drop
 * (thermal.h's talus_excess of the beds, with the slide angle); it writes what it gives per
 * metre of excess (1: m of pack per m of drop) into share (0 for others and where no
 * neighbour is steep enough). Branch-free, as thermal_share_cell. */
ERODEM_FN void snow_slide_share_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                           GLOBAL const real* bed, GLOBAL const real* snow,
                                           GLOBAL const real* dx, GLOBAL const real* dy,
                                           GLOBAL real* share, GLOBAL const real* area, real dt,
                                           ERODEM_P(SnowParams) p) {
  (void)area;
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real dist_t = centre_distance_y(dy, y - 1), dist_b = centre_distance_y(dy, y);
  const real total = talus_excess_out(
      bed[i], bed[i - 1], bed[i + 1], bed[i - W], bed[i + W], kind[i - 1] == ERODEM_CELL_ACTIVE,
      kind[i + 1] == ERODEM_CELL_ACTIVE, kind[i - W] == ERODEM_CELL_ACTIVE,
      kind[i + W] == ERODEM_CELL_ACTIVE, dx[y], dist_t, dist_b, p.tan_slide);
  const real k = p.slide_rate * dt;
  const real given = (k < (real)1 ? k : (real)1) * snow[i];
  const int slides = active & (total > (real)0);
  share[i] = slides ? given / (total > (real)0 ? total : (real)1) : (real)0;
}

/* Sliding, pass 2 (the generic sweep "snow_slide"), padded cell (x, y) of a row
 * 1 <= y <= H - 2: an active cell's pack loses share_i times its own excess drops and gains
 * each neighbour's share times that neighbour's excess drop towards it, times the neighbour's
 * area over its own (the same numbers on both sides: conservative to rounding; a pack that
 * gives all it has is set to 0, never below). Others keep theirs. */
ERODEM_FN void snow_slide_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL real* snow,
                                     GLOBAL const real* dx, GLOBAL const real* dy,
                                     GLOBAL const real* share, GLOBAL const real* area, real dt,
                                     ERODEM_P(SnowParams) p) {
  (void)dt;
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b = bed[i], t = p.tan_slide, s = snow[i];
  const real dist_x = dx[y], dist_t = centre_distance_y(dy, y - 1),
             dist_b = centre_distance_y(dy, y);
  const int has_l = kind[i - 1] == ERODEM_CELL_ACTIVE, has_r = kind[i + 1] == ERODEM_CELL_ACTIVE;
  const int has_t = kind[i - W] == ERODEM_CELL_ACTIVE, has_b = kind[i + W] == ERODEM_CELL_ACTIVE;
  const real b_l = bed[i - 1], b_r = bed[i + 1], b_t = bed[i - W], b_b = bed[i + W];
  const real out = talus_excess_out(b, b_l, b_r, b_t, b_b, has_l, has_r, has_t, has_b, dist_x,
                                    dist_t, dist_b, t);
  const real a = area[y];
  const real in_x = (has_l ? share[i - 1] * talus_excess(b_l, b, dist_x, t) : (real)0) +
                    (has_r ? share[i + 1] * talus_excess(b_r, b, dist_x, t) : (real)0);
  const real in_t = has_t ? share[i - W] * talus_excess(b_t, b, dist_t, t) : (real)0;
  const real in_b = has_b ? share[i + W] * talus_excess(b_b, b, dist_b, t) : (real)0;
  const real kept = s - share[i] * out;
  const real s_new = (kept > (real)0 ? kept : (real)0) + in_x + in_t * (area[y - 1] / a) +
                     in_b * (area[y + 1] / a);
  snow[i] = active ? s_new : s;
}

ERODEM_END_NAMESPACE

#endif
