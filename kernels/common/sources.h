/* erodem — sources (MODEL.md step 1) and evaporation (step 7). */
#ifndef ERODEM_KERNELS_COMMON_SOURCES_H
#define ERODEM_KERNELS_COMMON_SOURCES_H

#include "compat.h"

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

ERODEM_END_NAMESPACE

#endif
