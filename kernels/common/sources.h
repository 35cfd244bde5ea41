/* erodem — sources (MODEL.md step 1) and evaporation (step 7). */
#ifndef ERODEM_KERNELS_COMMON_SOURCES_H
#define ERODEM_KERNELS_COMMON_SOURCES_H

#include "compat.h"

/* The run constants of evaporation and the wetness (evaporation_params,
 * kernels/cell_params.cpp). */
ERODEM_PARAMS_BEGIN(EvaporationParams)
  real rate;         /* K_e (1/s) */
  real wetness_time; /* tau of the wetness running mean (s) */
  int evaporate;     /* rate > 0: 1, else 0 (then only the wetness runs) */
ERODEM_PARAMS_END(EvaporationParams)

ERODEM_BEGIN_NAMESPACE

/* Rain on one active cell: d += dt * rate * factor; rate (m/s), factor (1), dt (s). */
ERODEM_FN real rain_cell(real depth, real dt, real rate, real factor) {
  return depth + dt * rate * factor;
}

/* Evaporation of one active cell: d *= 1 - min(1, K_e dt). Returns the new depth and writes
 * the volume evaporated (m^3) through *lost; rate K_e (1/s), cell_area (m^2). */
ERODEM_FN real evaporation_cell(real depth, real dt, real rate, real cell_area, real* lost) {
  const real k = rate * dt;
  const real fraction = k < (real)1 ? k : (real)1;
  const real taken = depth * fraction;
  *lost = taken * cell_area;
  return depth - taken;
}

/* Running mean of depth with time constant tau (s): the wetness that drives mud and
 * vegetation classes (m). */
ERODEM_FN real wetness_cell(real wetness, real depth, real dt, real tau) {
  const real k = dt / tau;
  return wetness + (depth - wetness) * (k < (real)1 ? k : (real)1);
}

/* The rain sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both backends'
 * loops (kernels/cpu/sources.cpp, kernels/opencl/sources.cl): active cells take the rain of
 * rate (m/s) times their factor over dt (s); others keep their depth. The rain factor array
 * holds factor_pitch values per row (param_index, compat.h). */
ERODEM_FN void rain_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                               GLOBAL real* depth, GLOBAL const real* rain_factor, int factor_pitch,
                               real dt, real rate) {
  const int i = x + y * W;
  const real d = depth[i];
  const real f = rain_factor[param_index(x, y, factor_pitch)];
  depth[i] = kind[i] == ERODEM_CELL_ACTIVE ? rain_cell(d, dt, rate, f) : d;
}

/* The evaporation sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both
 * backends' loops (kernels/cpu/sources.cpp, kernels/opencl/evaporation.cl): active cells
 * (1 <= x <= W - 2, kind active) lose depth (when p.evaporate) and update their wetness from
 * the new depth; others keep theirs. Writes the volume evaporated (m^3; 0 for others) through
 * *lost. Branch-free. */
ERODEM_FN void evaporation_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                      GLOBAL real* depth, GLOBAL real* wetness,
                                      GLOBAL const real* area, real dt,
                                      ERODEM_P(EvaporationParams) p, real* lost) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const int dries = active & (p.evaporate != 0);
  const real d = depth[i], w = wetness[i]; /* unconditional loads: if-convertible */
  real taken;
  const real d_evaporated = evaporation_cell(d, dt, p.rate, area[y], &taken);
  const real d_new = dries ? d_evaporated : d;
  depth[i] = d_new;
  wetness[i] = active ? wetness_cell(w, d_new, dt, p.wetness_time) : w;
  *lost = dries ? taken : (real)0;
}

ERODEM_END_NAMESPACE

#endif
