/* erodem — erosion and deposition with a transport-capacity law (MODEL.md step 4). */
#ifndef ERODEM_KERNELS_COMMON_EROSION_H
#define ERODEM_KERNELS_COMMON_EROSION_H

#include "compat.h"
#include "compensated.h"

/* The run constants of the erosion process (erosion_params, kernels/cell_params.cpp, from
 * Params::Erosion). */
ERODEM_PARAMS_BEGIN(ErosionParams)
  real capacity_k;      /* K_c (s): capacity per unit speed and tilt */
  real dissolving_rate; /* K_s (1/s) */
  real deposition_rate; /* K_d (1/s) */
  real min_tilt;        /* sin_min (1) */
  real min_depth;       /* depth below which the capacity ramps to 0 (m); 0 = off */
  real bedrock;         /* no erosion below this bed elevation (m); -inf without one */
  int hardness_pitch;   /* values per row of the hardness array (param_index, compat.h) */
ERODEM_PARAMS_END(ErosionParams)

/* The run constants of the physical erosion law (erosion.law = "physical", docs/model.md
 * section 3.5.2; sediment_params_of, kernels/cell_params.hpp, from Params::Erosion): one
 * grain-size class in suspension over a bed of two layers, the loose soil over the bedrock,
 * each with its closure. Derived constants are computed once on the host in double. */
ERODEM_PARAMS_BEGIN(SedimentParams)
  real rho;               /* water density (kg/m^3), flow.water_density */
  real gravity;           /* g (m/s^2) */
  real min_depth;         /* h_min (m): numerics.velocity_min_depth, the thin-film depth */
  real shields_scale;     /* (rho_s - rho) g D (Pa): the Shields number is tau / this */
  real skin_n2;           /* n'^2 (s^2 m^-2/3): the grain roughness of Manning-Strickler */
  real settling;          /* w_s (m/s): settling velocity of the grains */
  real shields_flat;      /* theta_c on a flat bed (1): Soulsby-Whitehouse or given */
  real shields_slope;     /* Lamb et al. (2008): theta_c >= this * S^(1/4) (1); 0 = off */
  real total_load;        /* 0.05 sqrt(R g D^3) (m^2/s): Engelund-Hansen's transport scale */
  real pickup_z;          /* sqrt(R g D) Re_p^0.6 / w_s (1): Garcia-Parker's Z per sqrt(theta') */
  real max_concentration; /* c_max (1): cap of the equilibrium volume concentration */
  int pickup;             /* 0: Engelund-Hansen c_eq, 1: Garcia-Parker pick-up */
  int soil_cohesive;      /* the soil's closure: 0 non-cohesive, 1 cohesive */
  int rock_cohesive;      /* the bedrock's closure */
  real soil_bulk;         /* 1 / (1 - phi_soil) (1): bed thickness per solid thickness */
  real rock_bulk;         /* 1 / (1 - phi_rock) (1) */
  real soil_rate;         /* non-cohesive: pick-up multiplier (1); cohesive: M / rho_s (m/s) */
  real rock_rate;         /* the bedrock's */
  real soil_inv_tau_e;    /* cohesive: 1 / tau_c,e (1/Pa), the erosion threshold */
  real rock_inv_tau_e;    /* the bedrock's */
  real soil_inv_tau_d;    /* cohesive: 1 / tau_c,d (1/Pa) of Krone's deposition; 0 = always */
  real rock_inv_tau_d;    /* the bedrock's */
  real morfac;            /* morphological acceleration factor (1): bed change per exchange */
  int manning_pitch;      /* values per row of the Manning n array (param_index, compat.h) */
  int hardness_pitch;     /* values per row of the hardness array */
ERODEM_PARAMS_END(SedimentParams)

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

/* Squared tangent of the local bed slope, |grad z|^2 (1), from central differences of the bed
 * over active neighbours (one-sided at the edge of the active area; 0 without neighbours). */
ERODEM_FN real bed_slope_tan2(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                              GLOBAL const real* bed, GLOBAL const real* dx,
                              GLOBAL const real* dy) {
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
  return gx * gx + gy * gy;
}

/* Sine of the local bed tilt, from bed_slope_tan2: sqrt(tan^2 / (1 + tan^2)). */
ERODEM_FN real bed_tilt_sin(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                            GLOBAL const real* bed, GLOBAL const real* dx, GLOBAL const real* dy) {
  const real tan2 = bed_slope_tan2(x, y, W, kind, bed, dx, dy);
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
  const real k_erode = p.dissolving_rate * hardness[param_index(x, y, p.hardness_pitch)] * dt;
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
 * kind active) keep the result: the new bed through *bed_new (the kernel stores it in a second
 * buffer, the CPU loop in a row it writes back once no row reads the old bed there), the new
 * residual and sediment in place; the others keep theirs. Writes the volume eroded and the volume
 * deposited (m^3; 0 for other cells) through *eroded and *deposited. Every load is unconditional
 * (the row's area too: under `active`, PoCL made it a gather and left the kernel scalar), so loops
 * over x vectorise. */
ERODEM_FN void erosion_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL real* bed_residual,
                                  GLOBAL real* sediment, GLOBAL const real* depth,
                                  GLOBAL const real* velocity_x, GLOBAL const real* velocity_y,
                                  GLOBAL const real* hardness, GLOBAL const real* dx,
                                  GLOBAL const real* dy, GLOBAL const real* area, real dt,
                                  ERODEM_P(ErosionParams) p, real* bed_new, real* eroded,
                                  real* deposited) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b = bed[i], lo = bed_residual[i], s = sediment[i], cell_area = area[y];
  real lo_new, s_new, moved;
  const real b_new = erosion_cell(x, y, W, kind, bed, bed_residual, sediment, depth, velocity_x,
                                  velocity_y, hardness, dx, dy, dt, p, &lo_new, &s_new, &moved);
  *bed_new = active ? b_new : b;
  bed_residual[i] = active ? lo_new : lo;
  sediment[i] = active ? s_new : s;
  const real volume = moved * cell_area;
  *eroded = active & (volume > 0) ? volume : (real)0;
  *deposited = active & (volume < 0) ? -volume : (real)0;
}

/* ---- the physical law (erosion.law = "physical", docs/model.md section 3.5) ------------ */

/* Settling velocity (m/s) of natural grains of sieve diameter D (m), Ferguson & Church (2004):
 *   w_s = R g D^2 / (C1 nu + sqrt(0.75 C2 R g D^3)),
 * submerged specific gravity R = rho_s / rho - 1 (1), kinematic viscosity nu (m^2/s), C1 = 18
 * and C2 = 1 (natural sieved grains; 0.4 for smooth spheres, 1.2 for angular grains). */
ERODEM_FN real ferguson_church_settling(real grain, real specific_r, real g, real nu, real c2) {
  const real rgd = specific_r * g * grain;
  return rgd * grain / ((real)18 * nu + sqrt((real)0.75 * c2 * rgd * grain * grain));
}

/* Critical Shields number (1) on a flat bed of grains D (m), Soulsby & Whitehouse (1997):
 *   theta_c = 0.30 / (1 + 1.2 D*) + 0.055 (1 - exp(-0.020 D*)),  D* = D (R g / nu^2)^(1/3). */
ERODEM_FN real soulsby_whitehouse_shields(real grain, real specific_r, real g, real nu) {
  const real d_star = grain * cbrt(specific_r * g / (nu * nu));
  return (real)0.30 / ((real)1 + (real)1.2 * d_star) +
         (real)0.055 * ((real)1 - exp((real)-0.020 * d_star));
}

/* What the flow does to the bed at one cell: the bed shear stress and its Shields numbers. */
ERODEM_STRUCT_BEGIN(BedLoad)
  real tau;        /* tau_b (Pa), bed_shear_stress */
  real theta;      /* tau_b / ((rho_s - rho) g D) (1) */
  real theta_skin; /* theta' (1): with the grain roughness n' (<= n) in place of n */
  real theta_crit; /* theta_c (1): Soulsby-Whitehouse, raised on slopes (Lamb et al. 2008) */
ERODEM_STRUCT_END(BedLoad)

/* The bed load of a cell with depth h (m), velocities u, v (m/s), Manning n (s m^-1/3) and
 * squared bed slope tan2 (1). The skin friction (Einstein's partition): the same flow over
 * grain roughness n' = k_s^(1/6) / (8.1 sqrt g), k_s = 2.5 D, so tau' = tau n'^2 / n^2 (n' > n:
 * tau' = tau). Lamb et al. (2008): theta_c = max(theta_c,flat, 0.15 S^(1/4)), S = tan (the
 * fourth root as two square roots, the same bits everywhere). */
ERODEM_FN ERODEM_S(BedLoad)
    bed_load_of(real h, real u, real v, real n, real tan2, ERODEM_P(SedimentParams) p) {
  ERODEM_S(BedLoad) r;
  r.tau = bed_shear_stress(h, u, v, n, p.rho, p.gravity, p.min_depth);
  const real n2 = n * n;
  /* n'^2 / max(n^2, n'^2): 1 (exactly) where the grains are the rougher; one unconditional
   * division (a division under a condition stays a branch, and the loop is not vectorised) */
  const real skin = p.skin_n2 / (p.skin_n2 < n2 ? n2 : p.skin_n2);
  r.theta = r.tau / p.shields_scale;
  r.theta_skin = r.theta * skin;
  const real slope_crit = p.shields_slope * sqrt(sqrt(sqrt(tan2)));
  r.theta_crit = p.shields_flat > slope_crit ? p.shields_flat : slope_crit;
  return r;
}

/* Equilibrium volume concentration c_eq (1) of non-cohesive grains, capped at c_max:
 * - Engelund & Hansen (1967) total load, q_t = 0.05 sqrt(R g D^3) theta_e^(5/2) / c_f with
 *   the friction coefficient c_f = g n^2 / h^(1/3), carried at the depth-averaged speed:
 *   c_eq = q_t / (|u| h). Below the threshold nothing moves: theta_e = theta (1 - theta_c /
 *   theta'), the excess of the skin Shields number over theta_c, scaled to the total stress
 *   (erodem's threshold; theta_e -> theta far above it);
 * - Garcia & Parker (1991) pick-up, E_s = A Z^5 / (1 + A Z^5 / 0.3), A = 1.3e-7,
 *   Z = u*' Re_p^0.6 / w_s with u*' = sqrt(tau' / rho) = sqrt(theta' R g D); 0 below the
 *   threshold.
 * h_f is the depth, at least h_min (thin films: c_f and q_t / h grow without bound as h -> 0,
 * and c_max caps what is left). */
ERODEM_FN real equilibrium_concentration(real h_f, real speed, real n, ERODEM_S(BedLoad) b,
                                         ERODEM_P(SedimentParams) p) {
  const int moves = b.theta_skin > b.theta_crit;
  /* Engelund-Hansen: theta_e^(5/2) / (c_f |u| h) = theta_e^2 sqrt(theta_e) h^(1/3) / (g n^2 |u| h)
   */
  const real ratio = b.theta_crit / (moves ? b.theta_skin : (real)1);
  const real excess = moves ? b.theta * ((real)1 - ratio) : (real)0;
  const real denom = p.gravity * n * n * speed * h_f;
  const real eh = p.total_load * excess * excess * sqrt(excess) * erodem_cbrt_positive(h_f) /
                  (moves ? denom : (real)1);
  /* Garcia-Parker */
  const real z = sqrt(b.theta_skin) * p.pickup_z;
  const real z5 = (real)1.3e-7 * (z * z) * (z * z) * z;
  const real gp = z5 / ((real)1 + z5 / (real)0.3);
  const real c = moves ? (p.pickup ? gp : eh) : (real)0;
  return c < p.max_concentration ? c : p.max_concentration;
}

/* dt (1 - exp(-k dt)) / (k dt): the weight of a constant source over a step of the exact
 * solution of ds/dt = a - k s (k >= 0), dt at k = 0 (compat.h erodem_relax_weight). */
ERODEM_FN real relaxation_weight(real k, real dt) {
  return dt * erodem_relax_weight(k * dt);
}

/* One layer's exchange between the bed and the suspended sediment s (m of solid) of a cell,
 * written ds/dt = a - k s: a (m/s) the entrainment, k s (m/s) the deposition.
 * - non-cohesive: a = rate R w_s c_eq, k = w_s / h (the well-mixed column: E - D = w_s (R c_eq -
 *   c) with c = s / h);
 * - cohesive (Partheniades 1965; Krone 1962): a = R (M / rho_s) max(tau / tau_e - 1, 0),
 *   k = w_s / h max(1 - tau / tau_d, 0) (1 without tau_d).
 * h is at least h_min. Returns s after dt (s), the exact solution for a and k held over the
 * step: s e^(-k dt) + a dt (1 - e^(-k dt)) / (k dt). */
ERODEM_FN real layer_exchange(int cohesive, real rate, real inv_tau_e, real inv_tau_d, real s,
                              real h_f, real hardness, real c_eq, real tau, real dt,
                              ERODEM_P(SedimentParams) p) {
  const real settle = p.settling / h_f;
  const real krone = (real)1 - tau * inv_tau_d;
  /* the closure chosen by products with 1 and 0 (exact: both terms are finite), not by a
   * select on the int: GCC does not vectorise the loop with that one ("no vectype") */
  const real coh = (real)cohesive;
  const real k = settle * (coh * (krone > (real)0 ? krone : (real)0) + ((real)1 - coh));
  const real excess = tau * inv_tau_e - (real)1;
  const real a =
      hardness * rate *
      (coh * (excess > (real)0 ? excess : (real)0) + ((real)1 - coh) * (p.settling * c_eq));
  return s * erodem_exp_neg(k * dt) + a * relaxation_weight(k, dt);
}

/* Erosion / deposition of the physical law at active padded cell (x, y). The soil (loose
 * layer, thickness L = soil[i] in m of bed) lies over the bedrock; the surface layer's closure
 * moves solid m (m; negative: deposition) into suspension, the bed lowers by m / (1 - phi) of
 * the layer it comes from (Exner with porosity; deposits join the soil). Where the soil runs
 * out within the step, the rest of the step (in proportion) erodes the bedrock with its
 * closure from the sediment the soil gave. With morfac, the bed changes morfac times what
 * the suspension gains. Returns the new bed (m) and writes the residual, the sediment (m of
 * solid), the soil thickness (m), the solid taken from the bedrock (m) and the bed's bulk change
 * minus the solid moved (m: the pores opened, and morfac's extra) through the pointers. */
ERODEM_FN real sediment_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                             GLOBAL const real* bed, GLOBAL const real* bed_residual,
                             GLOBAL const real* sediment, GLOBAL const real* soil,
                             GLOBAL const real* depth, GLOBAL const real* velocity_x,
                             GLOBAL const real* velocity_y, GLOBAL const real* manning,
                             GLOBAL const real* hardness, GLOBAL const real* dx,
                             GLOBAL const real* dy, real dt, ERODEM_P(SedimentParams) p,
                             real* bed_residual_out, real* sediment_out, real* soil_out,
                             real* moved_out, real* rock_out, real* bulking_out) {
  const int i = x + y * W;
  const real h = depth[i], u = velocity_x[i], v = velocity_y[i];
  const real n = manning[param_index(x, y, p.manning_pitch)];
  const real s = sediment[i], soil_l = soil[i], r = hardness[param_index(x, y, p.hardness_pitch)];
  const real tan2 = bed_slope_tan2(x, y, W, kind, bed, dx, dy);
  const ERODEM_S(BedLoad) b = bed_load_of(h, u, v, n, tan2, p);
  const real speed = sqrt(u * u + v * v);
  const real h_f = h > p.min_depth ? h : p.min_depth;
  const real c_eq = equilibrium_concentration(h_f, speed, n, b, p);
  /* the soil first while there is some, then the bedrock. The choices between the layers are
   * blends by 1 and 0 (exact: every term is finite), not selects on their conditions: GCC
   * does not vectorise the loop with those (a select between masks of the float compares in a
   * loop that also compares the bytes of the kinds: "conversion not supported by target"). */
  const real on_soil = (real)(soil_l > (real)0);
  const real s_soil = layer_exchange(p.soil_cohesive, p.soil_rate, p.soil_inv_tau_e,
                                     p.soil_inv_tau_d, s, h_f, r, c_eq, b.tau, dt, p);
  const real s_rock = layer_exchange(p.rock_cohesive, p.rock_rate, p.rock_inv_tau_e,
                                     p.rock_inv_tau_d, s, h_f, r, c_eq, b.tau, dt, p);
  const real m_first = (on_soil * s_soil + ((real)1 - on_soil) * s_rock) - s;
  /* the solid the soil holds (m), in exchanged solid: the bed takes morfac times it */
  const real solid_soil = soil_l / (p.soil_bulk * p.morfac);
  const real m_soil_room = m_first - solid_soil;
  const real runs_out = on_soil * (real)(m_soil_room > (real)0);
  /* the rest of the step on the bedrock, from the sediment the soil gave (m_first > 0 where
   * the soil runs out) */
  const real rest = runs_out * (m_soil_room / (m_first > (real)0 ? m_first : (real)1));
  const real s1 = s + solid_soil;
  const real s_after = layer_exchange(p.rock_cohesive, p.rock_rate, p.rock_inv_tau_e,
                                      p.rock_inv_tau_d, s1, h_f, r, c_eq, b.tau, rest * dt, p);
  const real m_second = s_after - s1;
  const real gain_1 = m_first > (real)0 ? m_first : (real)0, loss_1 = m_first - gain_1;
  const real gain_2 = m_second > (real)0 ? m_second : (real)0, loss_2 = m_second - gain_2;
  /* solid from (+) or to (-) the soil and from the bedrock */
  const real from_soil = runs_out * (solid_soil + loss_2) +
                         ((real)1 - runs_out) * (on_soil * m_first + ((real)1 - on_soil) * loss_1);
  const real from_rock = runs_out * gain_2 + ((real)1 - runs_out) * (((real)1 - on_soil) * gain_1);
  const real moved = from_soil + from_rock;
  const real lowered = p.morfac * (from_soil * p.soil_bulk + from_rock * p.rock_bulk);
  const real soil_new = soil_l - p.morfac * from_soil * p.soil_bulk;
  real e_s, e_b;
  const real s_new = two_sum(s, moved, &e_s); /* s + moved = s_new + e_s */
  const real bed_new = two_sum(bed[i], -lowered, &e_b);
  *sediment_out = s_new;
  /* where the soil ran out it is gone (not a rounding residue of soil - its solid times bulk) */
  *soil_out = ((real)1 - runs_out) * (soil_new > (real)0 ? soil_new : (real)0);
  *moved_out = moved;
  *rock_out = from_rock;
  *bulking_out = lowered - moved;
  /* the sediment kept e_s less than moved: the bed gives that back, in the surface's bulk */
  const real bulk = on_soil * p.soil_bulk + ((real)1 - on_soil) * p.rock_bulk;
  return two_sum(bed_new, (bed_residual[i] + e_b) + e_s * bulk * p.morfac, bed_residual_out);
}

/* The physical erosion sweep's work for padded cell (x, y) of a row 1 <= y <= H - 2 (the CPU
 * loop of kernels/cpu/erosion.cpp, the kernel erosion_physical of kernels/opencl/erosion.cl):
 * the active cells keep sediment_cell's results, the others theirs: the new bed through
 * *bed_new (as erosion_sweep_cell), the rest in place. Writes the volumes (m^3 of
 * solid; 0 for other cells) eroded, deposited and taken from the bedrock, and the bed's bulk
 * change minus the solid moved (m^3) through the pointers. Branch-free. */
ERODEM_FN void sediment_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                   GLOBAL const real* bed, GLOBAL real* bed_residual,
                                   GLOBAL real* sediment, GLOBAL real* soil,
                                   GLOBAL const real* depth, GLOBAL const real* velocity_x,
                                   GLOBAL const real* velocity_y, GLOBAL const real* manning,
                                   GLOBAL const real* hardness, GLOBAL const real* dx,
                                   GLOBAL const real* dy, GLOBAL const real* area, real dt,
                                   ERODEM_P(SedimentParams) p, real* bed_new, real* eroded,
                                   real* deposited, real* eroded_rock, real* bulking) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  const real b = bed[i], lo = bed_residual[i], s = sediment[i], l = soil[i], cell_area = area[y];
  real lo_new, s_new, l_new, moved, rock, bulk;
  const real b_new = sediment_cell(x, y, W, kind, bed, bed_residual, sediment, soil, depth,
                                   velocity_x, velocity_y, manning, hardness, dx, dy, dt, p,
                                   &lo_new, &s_new, &l_new, &moved, &rock, &bulk);
  *bed_new = active ? b_new : b;
  bed_residual[i] = active ? lo_new : lo;
  sediment[i] = active ? s_new : s;
  soil[i] = active ? l_new : l;
  const real volume = moved * cell_area;
  *eroded = active & (volume > 0) ? volume : (real)0;
  *deposited = active & (volume < 0) ? -volume : (real)0;
  *eroded_rock = active ? rock * cell_area : (real)0;
  *bulking = active ? bulk * cell_area : (real)0;
}

ERODEM_END_NAMESPACE

#endif
