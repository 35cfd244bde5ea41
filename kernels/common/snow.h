/* erodem — the snow pack (MODEL.md step 8): snow water equivalent that melts by a degree-day
 * rule (Hock 2003) with an elevation lapse rate, the melt entering the water depth. */
#ifndef ERODEM_KERNELS_COMMON_SNOW_H
#define ERODEM_KERNELS_COMMON_SNOW_H

#include "compat.h"

/* The run constants of the snow pack (snow_params, kernels/cell_params.cpp). */
ERODEM_PARAMS(SnowParams, {
  real melt_factor;         /* DDF, melt per kelvin above melt_temperature (m/s per K) */
  real melt_temperature;    /* T_melt (degrees C) */
  real air_temperature;     /* T_ref at reference_elevation (degrees C) */
  real reference_elevation; /* z_ref (m) */
  real lapse_rate;          /* dT/dz (K/m) */
})

ERODEM_BEGIN_NAMESPACE

/* The air temperature at elevation z (m): T_ref + lapse_rate (z - z_ref) (degrees C). */
ERODEM_FN real snow_air_temperature(real z, ERODEM_P(SnowParams) p) {
  return p.air_temperature + p.lapse_rate * (z - p.reference_elevation);
}

/* The melt of one cell in dt (s): DDF max(0, T - T_melt) dt, never more than the pack `snow`
 * (m of water equivalent); T at the bed elevation `bed` (m). */
ERODEM_FN real snow_melt_cell(real snow, real bed, real dt, ERODEM_P(SnowParams) p) {
  const real excess = snow_air_temperature(bed, p) - p.melt_temperature;
  const real potential = p.melt_factor * (excess > (real)0 ? excess : (real)0) * dt;
  return potential < snow ? potential : snow;
}

/* The snow sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both backends'
 * loops (the generic sweep "snow": kernels/cpu/sweeps.cpp, kernels/opencl/snow.cl): active
 * cells (1 <= x <= W - 2, kind active) melt snow_melt_cell of their pack into their depth;
 * others keep both. Writes the volume melted (m^3; 0 for others) through *melted.
 * Branch-free. */
ERODEM_FN void snow_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                               GLOBAL const real* bed, GLOBAL real* snow, GLOBAL real* depth,
                               GLOBAL const real* area, real dt, ERODEM_P(SnowParams) p,
                               real* melted) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real s = snow[i], d = depth[i]; /* unconditional loads: if-convertible */
  const real m = active ? snow_melt_cell(s, bed[i], dt, p) : (real)0;
  snow[i] = s - m;
  depth[i] = d + m;
  *melted = m * area[y];
}

ERODEM_END_NAMESPACE

#endif
