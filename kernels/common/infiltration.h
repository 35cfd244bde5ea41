/* erodem — infiltration (issue 18): Green-Ampt (1911) with the implicit cumulative relation
 * per step, a finite soil store, and the recovery of the capacity between storms (SWMM's
 * Green-Ampt recovery, Rossman 2015). docs/model.md section 3.11. */
#ifndef ERODEM_KERNELS_COMMON_INFILTRATION_H
#define ERODEM_KERNELS_COMMON_INFILTRATION_H

#include "compat.h"

/* The run constants of infiltration (infiltration_params_of, kernels/cell_params.hpp). The
 * soil's K_sat, suction and store are per-cell fields (infiltration_ksat, _suction, _store). */
ERODEM_PARAMS_BEGIN(InfiltrationParams)
  real recovery_rate; /* k_r (1/s) where recovery_swmm is 0 */
  real swmm_scale;    /* recovery_swmm: k_r = sqrt(K_sat * swmm_scale) / 270000 (SWMM's rule in
                         K_sat (in/h) and 1/h: swmm_scale = 1 / (0.0254 m / 3600 s)) */
  int recovery_swmm;  /* 1: SWMM's k_r from K_sat; 0: recovery_rate */
ERODEM_PARAMS_END(InfiltrationParams)

ERODEM_BEGIN_NAMESPACE

/* u - ln(1 + u) for u >= 0 (1), without the cancellation of the difference where u is small:
 * below 1/16 the series u^2 (1/2 - u (1/3 - u (1/4 - ... u / 14))), truncated below 3e-17
 * relative; above it the difference, exact to 32 ulp relative there (at u = 1/16). */
ERODEM_FN real green_ampt_u_minus_log1p(real u) {
  if (!(u < (real)0.0625)) return u - log1p(u); /* one of the two: log1p is the dear part */
  real acc = (real)1 / (real)14;
  for (int k = 13; k >= 2; --k) acc = (real)1 / (real)k - u * acc;
  return u * u * acc;
}

/* The depth (m) a ponded soil takes in dt (s) from the infiltrated depth F (m): the D > 0 with
 *   D - S ln(1 + D / (F + S)) = K_sat dt,
 * the Green-Ampt relation F(t) - S ln(1 + F(t) / S) = K_sat t integrated from F over dt, exact
 * for any dt (the rate K_sat (1 + S / F) depends on F alone), S = psi * delta_theta (m).
 * Written F u + S (u - ln(1 + u)) = K_sat dt with u = D / (F + S) (no cancellation at F = 0).
 * Newton's method from the upper bound min(K dt + sqrt(2 S K dt), K dt (1 + S / F)) (the first
 * because e^b >= 1 + b + b^2 / 2, the second the rate at F held over dt): the left side is
 * convex and increasing in D, so the iterates fall monotonically to the root, quadratically
 * near it: they stop once a step moves D by less than 64 ulps (then the next would move it by
 * rounding), at most eight; for K dt / S from 3e-9 to 4e3 that is rounding in float32 and
 * float64 (tests/test_infiltration.cpp checks the closed form). 0 where K_sat is 0. */
ERODEM_FN real green_ampt_increment(real F, real ksat, real suction, real dt) {
  const real kdt = ksat * dt;
  const real a = F + suction;
  const real early = kdt + sqrt((real)2 * suction * kdt);
  const real held = F > (real)0 ? kdt + kdt * (suction / (F > (real)0 ? F : (real)1)) : early;
  real d = early < held ? early : held;
  const real scale = a > (real)0 ? a : (real)1; /* a = 0 only where S = F = 0: then D = K dt */
  const real tolerance = (real)64 * ERODEM_EPSILON(real);
  for (int it = 0; it < 8; ++it) {
    const real u = d / scale;
    /* F u = D where a = F + S > 0; where a = 0 the relation is D = K dt */
    const real g = (a > (real)0 ? F * u + suction * green_ampt_u_minus_log1p(u) : d) - kdt;
    const real slope = a > (real)0 ? (F + d) / (a + d) : (real)1;
    const real next = slope > (real)0 ? d - g / slope : d;
    const real moved = d - (next > kdt ? next : kdt);
    d = next > kdt ? next : kdt; /* the rate is never below K_sat */
    if (fabs(moved) <= tolerance * d) break;
  }
  return kdt > (real)0 ? d : (real)0;
}

/* What an active cell's soil takes in dt (s) from the water d (m) on it with room (m) left in
 * its store: min(green_ampt_increment, d, room), the Newton iterations only where they decide
 * it (D >= K_sat dt, so where K_sat dt covers the water, or there is no water or no room, the
 * minimum is known without them: dry cells, light rain, full stores cost a comparison). */
ERODEM_FN real green_ampt_take(real F, real ksat, real suction, real dt, real d, real room) {
  const real cap = d < room ? d : room;
  if (!(cap > (real)0) || ksat * dt >= cap) return cap > (real)0 ? cap : (real)0;
  const real potential = green_ampt_increment(F, ksat, suction, dt);
  return potential < cap ? potential : cap;
}

/* SWMM's recovery constant k_r (1/s) for K_sat (m/s), or the given rate. */
ERODEM_FN real infiltration_recovery_rate(real ksat, ERODEM_P(InfiltrationParams) p) {
  const real swmm = sqrt(ksat * p.swmm_scale) / (real)270000;
  return p.recovery_swmm ? swmm : p.recovery_rate;
}

/* The infiltration sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both
 * backends' loops (the generic sweep "infiltration": kernels/cpu/sweeps.cpp,
 * kernels/opencl/infiltration.cl). On an active cell with water d > 0 (m) the soil takes
 *   I = min(green_ampt_increment(F, K_sat, S, dt), d, F_max - F)
 * from the depth into F (`infiltrated`, m); on a dry one (d = 0) the store drains,
 * F <- F e^(-k_r dt) (the capacity recovers). Others keep their state. Writes the volumes
 * infiltrated and drained (m^3) through *infiltrated and *drained. */
ERODEM_FN void infiltration_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                       GLOBAL real* depth, GLOBAL real* infiltrated,
                                       GLOBAL const real* ksat, GLOBAL const real* suction,
                                       GLOBAL const real* store, GLOBAL const real* area, real dt,
                                       ERODEM_P(InfiltrationParams) p, real* infiltrated_volume,
                                       real* drained_volume) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real d = depth[i], F = infiltrated[i], k = ksat[i];
  const real room = store[i] - F > (real)0 ? store[i] - F : (real)0;
  const real take = active ? green_ampt_take(F, k, suction[i], dt, d, room) : (real)0;
  const real kept = F * erodem_exp_neg(infiltration_recovery_rate(k, p) * dt);
  const real drain = active & (d <= (real)0) ? F - kept : (real)0;
  depth[i] = d - take;
  infiltrated[i] = F + take - drain;
  *infiltrated_volume = take * area[y];
  *drained_volume = drain * area[y];
}

ERODEM_END_NAMESPACE

#endif
