/* erodem — thermal erosion / slope collapse (MODEL.md step 6), two gather passes. */
#ifndef ERODEM_KERNELS_COMMON_THERMAL_H
#define ERODEM_KERNELS_COMMON_THERMAL_H

#include "compat.h"
#include "compensated.h"

/* The run constants of slope collapse (thermal_params, kernels/cell_params.cpp). */
ERODEM_PARAMS_BEGIN(ThermalParams)
  real rate;          /* K_t (1/s) */
  real tan_talus;     /* tan of the talus angle (1) */
  real tan_wet;       /* tan of the wet talus angle (1); tan_talus where none is given */
  real wet_threshold; /* wetness (m) above which a cell takes tan_wet (+inf: no wet angle) */
  int by_class;       /* 1: the dry talus slope of each cell is its talus_slope field (the
                         terrain classes' table, terrain_class.h); 0: tan_talus everywhere */
ERODEM_PARAMS_END(ThermalParams)

ERODEM_BEGIN_NAMESPACE

/* The talus slope of cell j from its wetness (m, the running mean of its depth): the wet one
 * above the threshold (MODEL.md step 6: wet or soft ground stands less steep), else the dry
 * one, its class's (talus_slope, used only with by_class) or tan_talus. The giver's slope sets
 * each transfer. `talus` is an array of the grid's size either way (the backends pass another
 * field where the classes set no slopes), loaded unconditionally: under by_class, GCC's
 * x86-64-v2 build (no masked loads) left thermal collapse's loops scalar. */
ERODEM_FN real cell_tan_talus(GLOBAL const real* wetness, GLOBAL const real* talus, int j,
                              ERODEM_P(ThermalParams) p) {
  const real class_slope = talus[j];
  const real dry = p.by_class ? class_slope : p.tan_talus;
  return wetness[j] > p.wet_threshold ? p.tan_wet : dry;
}

/* Height (m) by which the bed drop from `from` to `to` over `dist` (m) exceeds the talus
 * slope tan_talus (1); 0 when it does not. */
ERODEM_FN real talus_excess(real from, real to, real dist, real tan_talus) {
  const real excess = from - to - dist * tan_talus;
  return excess > 0 ? excess : (real)0;
}

/* The sum of talus_excess from the bed `b` to each of its four neighbours (left, right, top,
 * bottom: beds b_l .. b_b at dist_x, dist_x, dist_t, dist_b m) that `has_*` marks; the others
 * add +0 (branch-free, the same sum as skipping them). */
ERODEM_FN real talus_excess_out(real b, real b_l, real b_r, real b_t, real b_b, int has_l,
                                int has_r, int has_t, int has_b, real dist_x, real dist_t,
                                real dist_b, real tan_talus) {
  return (has_l ? talus_excess(b, b_l, dist_x, tan_talus) : (real)0) +
         (has_r ? talus_excess(b, b_r, dist_x, tan_talus) : (real)0) +
         (has_t ? talus_excess(b, b_t, dist_t, tan_talus) : (real)0) +
         (has_b ? talus_excess(b, b_b, dist_b, tan_talus) : (real)0);
}

/* Pass 1, active padded cell (x, y): the volume to move,
 *   V = min(1, K_t dt) * area * (dh_max - dist tan(theta)) / 2,
 * shared among the lower active neighbours in proportion to their excess. Returns V per
 * metre of summed excess (m^2), which pass 2 multiplies by each neighbour's excess. */
ERODEM_FN real thermal_share_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL const real* wetness,
                                  GLOBAL const real* talus, GLOBAL const real* dx,
                                  GLOBAL const real* dy, GLOBAL const real* area, real dt,
                                  ERODEM_P(ThermalParams) p) {
  const int i = x + y * W;
  const real rate = p.rate, tan_talus = cell_tan_talus(wetness, talus, i, p);
  const real b = bed[i];
  const real dist_t = centre_distance_y(dy, y - 1);
  const real dist_b = centre_distance_y(dy, y);
  /* every load unconditional and every choice a select: branch-free, so loops vectorise */
  const real b_l = bed[i - 1], b_r = bed[i + 1], b_t = bed[i - W], b_b = bed[i + W];
  const real x_l = talus_excess(b, b_l, dx[y], tan_talus);
  const real x_r = talus_excess(b, b_r, dx[y], tan_talus);
  const real x_t = talus_excess(b, b_t, dist_t, tan_talus);
  const real x_b = talus_excess(b, b_b, dist_b, tan_talus);
  const real e_l = kind[i - 1] == ERODEM_CELL_ACTIVE ? x_l : (real)0;
  const real e_r = kind[i + 1] == ERODEM_CELL_ACTIVE ? x_r : (real)0;
  const real e_t = kind[i - W] == ERODEM_CELL_ACTIVE ? x_t : (real)0;
  const real e_b = kind[i + W] == ERODEM_CELL_ACTIVE ? x_b : (real)0;
  const real total = e_l + e_r + e_t + e_b;
  const int moves = total > 0;
  /* The largest excess as a chain, not as max(max(l, r), max(t, b)): from that pair of pairs
   * LLVM's SLP pass packed the four excesses two by two into vectors of two, and PoCL then
   * left thermal_share scalar across work-items on AVX2 (4.6 against 1.13 ms per call at
   * 1024^2; tests/pocl_vectorisation.sh, performance.md "PoCL's water update and thermal share
   * vectorised on AVX2").
   * The same value in any order: every e_* is +0 or positive, never NaN or -0. */
  const real m_lr = e_l > e_r ? e_l : e_r;
  const real m_lrt = m_lr > e_t ? m_lr : e_t;
  const real e_max = m_lrt > e_b ? m_lrt : e_b;
  const real k = rate * dt;
  const real volume = (k < (real)1 ? k : (real)1) * area[y] * e_max * (real)0.5;
  const real per_excess = volume / (moves ? total : (real)1);
  return moves ? per_excess : (real)0;
}

/* Pass 2, active padded cell (x, y): bed after the transfers of pass 1,
 *   b_i <- b_i + (sum_n share_n e(n->i) - share_i sum_n e(i->n)) / area_i,
 * added to the bed pair (bed, bed_residual; compensated.h): returns the new bed (m) and
 * writes the new residual (m) through *bed_residual_out and the volume the cell gave (m^3)
 * through *given_out. Every transfer is computed from the same numbers by giver and taker:
 * conservative. */
ERODEM_FN real thermal_apply_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL const real* bed_residual,
                                  GLOBAL const real* wetness, GLOBAL const real* talus,
                                  GLOBAL const real* share, GLOBAL const real* dx,
                                  GLOBAL const real* dy, GLOBAL const real* area,
                                  ERODEM_P(ThermalParams) p, real* bed_residual_out,
                                  real* given_out) {
  const int i = x + y * W;
  const real tan_talus = cell_tan_talus(wetness, talus, i, p);
  const real b = bed[i];
  const real dist_t = centre_distance_y(dy, y - 1);
  const real dist_b = centre_distance_y(dy, y);
  const real dist_x = dx[y], cell_area = area[y]; /* loaded unconditionally */
  /* inactive neighbours add +0 (branch-free, the same sums as skipping them) */
  const int has_l = kind[i - 1] == ERODEM_CELL_ACTIVE, has_r = kind[i + 1] == ERODEM_CELL_ACTIVE;
  const int has_t = kind[i - W] == ERODEM_CELL_ACTIVE, has_b = kind[i + W] == ERODEM_CELL_ACTIVE;
  const real b_l = bed[i - 1], b_r = bed[i + 1], b_t = bed[i - W], b_b = bed[i + W];
  const real given = talus_excess_out(b, b_l, b_r, b_t, b_b, has_l, has_r, has_t, has_b, dist_x,
                                      dist_t, dist_b, tan_talus);
  const real s_l = share[i - 1], s_r = share[i + 1], s_t = share[i - W], s_b = share[i + W];
  /* each neighbour gives at its own talus slope, as its pass 1 shared */
  const real t_l = cell_tan_talus(wetness, talus, i - 1, p),
             t_r = cell_tan_talus(wetness, talus, i + 1, p);
  const real t_t = cell_tan_talus(wetness, talus, i - W, p),
             t_b = cell_tan_talus(wetness, talus, i + W, p);
  const real taken = (has_l ? s_l * talus_excess(b_l, b, dist_x, t_l) : (real)0) +
                     (has_r ? s_r * talus_excess(b_r, b, dist_x, t_r) : (real)0) +
                     (has_t ? s_t * talus_excess(b_t, b, dist_t, t_t) : (real)0) +
                     (has_b ? s_b * talus_excess(b_b, b, dist_b, t_b) : (real)0);
  /* times the reciprocal of the row's area (one division per row, hoisted out of the cell
   * loops; dividing every cell took 12 % of the PoCL pass at 4096^2) */
  const real gave = share[i] * given;
  *given_out = gave;
  return bed_add(b, bed_residual[i], (taken - gave) * ((real)1 / cell_area), bed_residual_out);
}

/* The two sweeps of slope collapse for padded cell (x, y) of a row 1 <= y <= H - 2, the
 * bodies of both backends' loops (kernels/cpu/thermal.cpp, kernels/opencl/thermal.cl): every
 * cell computes, the active ones (1 <= x <= W - 2, kind active) keep the result, branch-free.
 * Pass 1 writes the share (0 for other cells); pass 2 writes the new bed through *bed_new (as
 * erosion_sweep_cell: a second buffer, or a row the CPU writes back once no row reads the old
 * bed there) and the residual in place (others keep theirs) and the volume the cell gave (m^3;
 * 0 for others) through *moved. */
ERODEM_FN void thermal_share_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                        GLOBAL const real* bed, GLOBAL const real* wetness,
                                        GLOBAL const real* talus, GLOBAL const real* dx,
                                        GLOBAL const real* dy, GLOBAL const real* area,
                                        GLOBAL real* share, real dt, ERODEM_P(ThermalParams) p) {
  const int i = x + y * W;
  const real s = thermal_share_cell(x, y, W, kind, bed, wetness, talus, dx, dy, area, dt, p);
  share[i] = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE) ? s : (real)0;
}

ERODEM_FN void thermal_apply_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                        GLOBAL const real* bed, GLOBAL real* bed_residual,
                                        GLOBAL const real* wetness, GLOBAL const real* talus,
                                        GLOBAL const real* share, GLOBAL const real* dx,
                                        GLOBAL const real* dy, GLOBAL const real* area,
                                        ERODEM_P(ThermalParams) p, real* bed_new, real* moved) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b_old = bed[i], lo_old = bed_residual[i]; /* unconditional loads */
  real lo_new, gave;
  const real b = thermal_apply_cell(x, y, W, kind, bed, bed_residual, wetness, talus, share, dx, dy,
                                    area, p, &lo_new, &gave);
  *bed_new = active ? b : b_old;
  bed_residual[i] = active ? lo_new : lo_old;
  *moved = active ? gave : (real)0;
}

ERODEM_END_NAMESPACE

#endif
