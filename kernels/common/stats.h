/* erodem — per-cell terms of the ledger's reductions and the stability check. */
#ifndef ERODEM_KERNELS_COMMON_STATS_H
#define ERODEM_KERNELS_COMMON_STATS_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Whether an active cell's state is physical: finite bed and sediment, depth >= 0 and
 * finite (NaN fails every comparison, so it fails here too). */
ERODEM_FN int cell_state_ok(real bed, real depth, real sediment) {
  return depth >= 0 && isfinite(depth) && isfinite(bed) && isfinite(sediment);
}

/* Courant number of the gravity wave in a cell: dt sqrt(g d) / dx_min (1). */
ERODEM_FN real wave_courant(real depth, real gravity, real dt, real dx_min) {
  return dt * sqrt(gravity * fmax(depth, (real)0)) / dx_min;
}

ERODEM_END_NAMESPACE

#endif
