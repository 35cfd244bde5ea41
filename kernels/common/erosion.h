/* erodem — erosion and deposition with a transport-capacity law (MODEL.md step 4). */
#ifndef ERODEM_KERNELS_COMMON_EROSION_H
#define ERODEM_KERNELS_COMMON_EROSION_H

#include "compat.h"
#include "compensated.h"

/* The run constants of the erosion process (erosion_params, kernels/cell_params.cpp, from
 * Params::Erosion). */
ERODEM_PARAMS(ErosionParams, {
  real capacity_k;      /* K_c (s): capacity per unit speed and tilt */
  real dissolving_rate; /* K_s (1/s) */
  real deposition_rate; /* K_d (1/s) */
  real min_tilt;        /* sin_min (1) */
  real min_depth;       /* depth below which the capacity ramps to 0 (m); 0 = off */
  real bedrock;         /* no erosion below this bed elevation (m); -inf without one */
})

ERODEM_BEGIN_NAMESPACE

/* Bed shear stress (Pa) of a cell with depth h (m), velocities u, v (m/s) and Manning n
 * (s m^-1/3): the friction term of the flow schemes, tau_b = rho g n^2 |u|^2 / h^(1/3), with water
 * density rho (kg/m^3) and gravity g (m/s^2). Thin films: the depth in h^(1/3) is at least h_min
 * (m, numerics.velocity_min_depth: the velocities are 0 or desingularised below it), so tau_b
 * stays bounded as h -> 0; 0 on a dry cell (h <= 0). */
ERODEM_FN real bed_shear_stress(real h, real u, real v, real n, real rho, real g, real h_min) {
  const real h_f = h > h_min ? h : h_min;
  const real tau = rho * g * n * n * (u * u + v * v) / erodem_cbrt_positive(h_f);
  return h > (real)0 ? tau : (real)0;
}

/* Sine of the local bed tilt from central differences of the bed over active neighbours
 * (one-sided at the edge of the active area). */
ERODEM_FN real bed_tilt_sin(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                            GLOBAL const real* bed, GLOBAL const real* dx, GLOBAL const real* dy) {
  const int i = x + y * W;
  const int has_l = kind[i - 1] == ERODEM_CELL_ACTIVE;
  const int has_r = kind[i + 1] == ERODEM_CELL_ACTIVE;
  const int has_t = kind[i - W] == ERODEM_CELL_ACTIVE;
  const int has_b = kind[i + W] == ERODEM_CELL_ACTIVE;
  /* every load unconditional and every choice a select: branch-free, so loops vectorise */
  const real b_c = bed[i], b_w = bed[i - 1], b_e = bed[i + 1], b_n = bed[i - W], b_s = bed[i + W];
  const real b_l = has_l ? b_w : b_c;
  const real b_r = has_r ? b_e : b_c;
  const real b_t = has_t ? b_n : b_c;
  const real b_b = has_b ? b_s : b_c;
  /* the central difference spans two cells, a one-sided one one cell, none no cell (then
   * the gradient is 0): the difference times the reciprocal of the span, chosen by the
   * neighbour counts among the row's reciprocals. Those are divisions of per-row numbers,
   * made unconditionally, so the cell loops hoist them; a division per cell under the
   * condition n > 0 made PoCL gather the row's spacing in every iteration (19.5 -> 16.8 ms
   * at 4096^2), and the count * spacing form lets PoCL's SLP vectoriser pack the x and y
   * parts into a 2-vector, after which PoCL does not vectorise across work-items. */
  const int n_x = has_l + has_r, n_y = has_t + has_b;
  const real dx_y = dx[y], dy_y = dy[y];
  const real inv_dx = (real)1 / dx_y, inv_2dx = (real)1 / (dx_y + dx_y);
  const real inv_dy = (real)1 / dy_y, inv_2dy = (real)1 / (dy_y + dy_y);
  const real per_span_x = n_x == 2 ? inv_2dx : (n_x == 1 ? inv_dx : (real)0);
  const real per_span_y = n_y == 2 ? inv_2dy : (n_y == 1 ? inv_dy : (real)0);
  const real gx = (b_r - b_l) * per_span_x; /* n_x = 0: b_r = b_l, so +0 */
  const real gy = (b_b - b_t) * per_span_y;
  const real tan2 = gx * gx + gy * gy;
  return sqrt(tan2 / ((real)1 + tan2));
}

/* Transport capacity C (m of bed-equivalent sediment):
 *   C = K_c * max(sin(tilt), sin_min) * |v| * g(d),
 * capacity K_c (s), speed |v| (m/s), g(d) = min(1, d / d_min_erosion) when d_min_erosion
 * (m) > 0, else 1. */
ERODEM_FN real transport_capacity(real capacity_k, real tilt_sin, real min_tilt, real speed,
                                  real depth, real min_depth) {
  const int limited = min_depth > 0;
  const real ratio = depth / (limited ? min_depth : (real)1);
  const real limiter = limited & (ratio < (real)1) ? ratio : (real)1;
  return capacity_k * (tilt_sin > min_tilt ? tilt_sin : min_tilt) * speed * limiter;
}

/* Erosion / deposition of active padded cell (x, y). If C > s, erode
 * min(1, K_s R dt) (C - s) from bed into suspension, never below `bedrock` (m); else
 * deposit min(1, K_d dt) (s - C). Reads bed (for the tilt) and its residual (the bed is the
 * pair bed + bed_residual, compensated.h); returns the new bed (m), writes the new residual
 * (m) through *bed_residual_out, the new suspended sediment (m) through *sediment_out and
 * the layer moved into suspension (m; negative where it deposits) through *moved_out.
 * Rates K_s, K_d (1/s); hardness R in [0, 1].
 *
 * The transfer is exact: the sediment takes fl(s + m) and so gains m - e exactly (TwoSum),
 * and the bed pair gives exactly m - e, so bed + sediment changes only by the rounding of
 * the residual (about 2^-24 ulp(bed) in float32). A plain float bed would keep only the part
 * of m above half an ulp of the bed: erosion and deposition below it were lost, or rounded
 * one way (docs/model.md section 1, "The bed is a compensated pair"). Branch-free (both cases
 * evaluated, one selected), so loops over cells vectorise. */
ERODEM_FN real erosion_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                            GLOBAL const real* bed, GLOBAL const real* bed_residual,
                            GLOBAL const real* sediment, GLOBAL const real* depth,
                            GLOBAL const real* velocity_x, GLOBAL const real* velocity_y,
                            GLOBAL const real* hardness, GLOBAL const real* dx,
                            GLOBAL const real* dy, real dt, ERODEM_P(ErosionParams) p,
                            real* bed_residual_out, real* sediment_out, real* moved_out) {
  const int i = x + y * W;
  const real u = velocity_x[i];
  const real v = velocity_y[i];
  const real speed = sqrt(u * u + v * v);
  const real tilt = bed_tilt_sin(x, y, W, kind, bed, dx, dy);
  const real capacity =
      transport_capacity(p.capacity_k, tilt, p.min_tilt, speed, depth[i], p.min_depth);
  const real s = sediment[i];
  const real b = bed[i];
  const real lo = bed_residual[i];
  const real k_erode = p.dissolving_rate * hardness[i] * dt;
  const real erode = (k_erode < (real)1 ? k_erode : (real)1) * (capacity - s);
  const real above = (b - p.bedrock) + lo; /* +inf without a bedrock level */
  const real above_rock = above > 0 ? above : (real)0;
  const real eroded = erode < above_rock ? erode : above_rock;
  const real k_deposit = p.deposition_rate * dt;
  const real deposited = -(k_deposit < (real)1 ? k_deposit : (real)1) * (s - capacity);
  const real moved = capacity > s ? eroded : deposited;
  real e_s, e_b;
  const real s_new = two_sum(s, moved, &e_s); /* s + moved = s_new + e_s */
  const real h = two_sum(b, -moved, &e_b);    /* b - moved = h + e_b */
  *sediment_out = s_new;
  *moved_out = moved;
  /* (b + lo) - (moved - e_s) = h + (lo + e_b + e_s) */
  return two_sum(h, (lo + e_b) + e_s, bed_residual_out);
}

/* The erosion sweep's work for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both
 * backends' sweeps (the CPU loop of kernels/cpu/erosion.cpp, the work-item of
 * kernels/opencl/erosion.cl): every cell computes (in the first and last column on
 * neighbours across the row's ends, inside the buffer) and the active ones (1 <= x <= W - 2,
 * kind active) keep the result: the new bed into bed_out, the new residual and sediment in
 * place; the others keep theirs. Writes the volume eroded and the volume deposited (m^3; 0
 * for other cells) through *eroded and *deposited. Every load is unconditional (the row's
 * area too: under `active`, PoCL made it a gather and left the kernel scalar), so loops over
 * x vectorise. */
ERODEM_FN void erosion_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL real* bed_out,
                                  GLOBAL real* bed_residual, GLOBAL real* sediment,
                                  GLOBAL const real* depth, GLOBAL const real* velocity_x,
                                  GLOBAL const real* velocity_y, GLOBAL const real* hardness,
                                  GLOBAL const real* dx, GLOBAL const real* dy,
                                  GLOBAL const real* area, real dt, ERODEM_P(ErosionParams) p,
                                  real* eroded, real* deposited) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b = bed[i], lo = bed_residual[i], s = sediment[i], cell_area = area[y];
  real lo_new, s_new, moved;
  const real b_new = erosion_cell(x, y, W, kind, bed, bed_residual, sediment, depth, velocity_x,
                                  velocity_y, hardness, dx, dy, dt, p, &lo_new, &s_new, &moved);
  bed_out[i] = active ? b_new : b;
  bed_residual[i] = active ? lo_new : lo;
  sediment[i] = active ? s_new : s;
  const real volume = moved * cell_area;
  *eroded = active & (volume > 0) ? volume : (real)0;
  *deposited = active & (volume < 0) ? -volume : (real)0;
}

ERODEM_END_NAMESPACE

#endif
