/* erodem — thermal erosion / slope collapse (MODEL.md step 6), two gather passes. */
#ifndef ERODEM_KERNELS_COMMON_THERMAL_H
#define ERODEM_KERNELS_COMMON_THERMAL_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Height (m) by which the bed drop from `from` to `to` over `dist` (m) exceeds the talus
 * slope tan_talus (1); 0 when it does not. */
ERODEM_FN real talus_excess(real from, real to, real dist, real tan_talus) {
  return fmax((real)0, from - to - dist * tan_talus);
}

/* Pass 1, active padded cell (x, y): the volume to move,
 *   V = min(1, K_t dt) * area * (dh_max - dist tan(theta)) / 2,
 * shared among the lower active neighbours in proportion to their excess. Returns V per
 * metre of summed excess (m^2), which pass 2 multiplies by each neighbour's excess. */
ERODEM_FN real thermal_share_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL const real* dx,
                                  GLOBAL const real* dy, GLOBAL const real* area, real dt,
                                  real rate, real tan_talus) {
  const int i = x + y * W;
  const real b = bed[i];
  const real dist_t = (real)0.5 * (dy[y] + dy[y - 1]);
  const real dist_b = (real)0.5 * (dy[y] + dy[y + 1]);
  const real e_l =
      kind[i - 1] == ERODEM_CELL_ACTIVE ? talus_excess(b, bed[i - 1], dx[y], tan_talus) : (real)0;
  const real e_r =
      kind[i + 1] == ERODEM_CELL_ACTIVE ? talus_excess(b, bed[i + 1], dx[y], tan_talus) : (real)0;
  const real e_t =
      kind[i - W] == ERODEM_CELL_ACTIVE ? talus_excess(b, bed[i - W], dist_t, tan_talus) : (real)0;
  const real e_b =
      kind[i + W] == ERODEM_CELL_ACTIVE ? talus_excess(b, bed[i + W], dist_b, tan_talus) : (real)0;
  const real total = e_l + e_r + e_t + e_b;
  if (!(total > 0)) return (real)0;
  const real e_max = fmax(fmax(e_l, e_r), fmax(e_t, e_b));
  const real volume = fmin((real)1, rate * dt) * area[y] * e_max * (real)0.5;
  return volume / total;
}

/* Pass 2, active padded cell (x, y): bed after the transfers of pass 1,
 *   b_i <- b_i + (sum_n share_n e(n->i) - share_i sum_n e(i->n)) / area_i.
 * Every transfer is computed from the same numbers by giver and taker: conservative. */
ERODEM_FN real thermal_apply_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL const real* share,
                                  GLOBAL const real* dx, GLOBAL const real* dy,
                                  GLOBAL const real* area, real tan_talus) {
  const int i = x + y * W;
  const real b = bed[i];
  const real dist_t = (real)0.5 * (dy[y] + dy[y - 1]);
  const real dist_b = (real)0.5 * (dy[y] + dy[y + 1]);
  real given = 0, taken = 0;
  if (kind[i - 1] == ERODEM_CELL_ACTIVE) {
    given += talus_excess(b, bed[i - 1], dx[y], tan_talus);
    taken += share[i - 1] * talus_excess(bed[i - 1], b, dx[y], tan_talus);
  }
  if (kind[i + 1] == ERODEM_CELL_ACTIVE) {
    given += talus_excess(b, bed[i + 1], dx[y], tan_talus);
    taken += share[i + 1] * talus_excess(bed[i + 1], b, dx[y], tan_talus);
  }
  if (kind[i - W] == ERODEM_CELL_ACTIVE) {
    given += talus_excess(b, bed[i - W], dist_t, tan_talus);
    taken += share[i - W] * talus_excess(bed[i - W], b, dist_t, tan_talus);
  }
  if (kind[i + W] == ERODEM_CELL_ACTIVE) {
    given += talus_excess(b, bed[i + W], dist_b, tan_talus);
    taken += share[i + W] * talus_excess(bed[i + W], b, dist_b, tan_talus);
  }
  return b + (taken - share[i] * given) / area[y];
}

ERODEM_END_NAMESPACE

#endif
