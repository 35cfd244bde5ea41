/* erodem — compensated (double-word) arithmetic for the bed elevation.
 *
 * The bed is an absolute elevation: in float32 one ulp is 6.1e-5 m at 1000 m and 9.8e-4 m at
 * 9000 m, while a step of erosion moves 1e-6 m or less. Added to a plain float bed such a
 * change rounds away (or rounds one way), and the eroded and deposited volumes drift from the
 * float64 ones by percents. So the bed is kept as a pair (hi, lo): hi is the bed the other
 * processes read (`bed`), lo the part below hi's precision (`bed_residual`), with
 * |lo| <= ulp(hi) / 2 after every update. The pair holds about twice the bits of `real`
 * (float32: 48 bits, 4e-12 m at 1000 m).
 *
 * These functions need round-to-nearest and no contraction into fused multiply-adds: the .cl
 * files set `FP_CONTRACT OFF`, the CPU kernels are built with -ffp-contract=off, and neither
 * build uses fast-math. */
#ifndef ERODEM_KERNELS_COMMON_COMPENSATED_H
#define ERODEM_KERNELS_COMMON_COMPENSATED_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Knuth's TwoSum: returns s = fl(a + b) and writes *err with a + b = s + *err exactly, for any
 * a and b (no ordering of magnitudes needed). */
ERODEM_FN real two_sum(real a, real b, real* err) {
  const real s = a + b;
  const real b_virtual = s - a;
  const real a_virtual = s - b_virtual;
  *err = (a - a_virtual) + (b - b_virtual);
  return s;
}

/* Adds `delta` (m) to the bed pair (hi, lo): returns the new hi and writes the new lo, with
 * hi' + lo' = hi + lo + delta up to one rounding of the small part (|error| <= ulp(lo')),
 * and |lo'| <= ulp(hi') / 2. */
ERODEM_FN real bed_add(real hi, real lo, real delta, real* lo_out) {
  real e;
  const real s = two_sum(hi, delta, &e);
  return two_sum(s, lo + e, lo_out);
}

ERODEM_END_NAMESPACE

#endif
