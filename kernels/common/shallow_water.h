/* erodem — the shallow-water scheme (flow.scheme = "shallow_water"): a cell-centred,
 * first-order Godunov finite-volume solver of the 2D shallow-water equations
 *
 *   dh/dt + div(q) = 0
 *   dq/dt + div(q u + g h^2 / 2 I) = -g h grad(z) - g n^2 |q| q / h^(7/3)
 *
 * with HLLC fluxes (Toro 2001), the hydrostatic reconstruction of Chen & Noelle (2017) at
 * every face (well balanced, positive, and with a bed-slope force that does not vanish for a
 * film thinner than the bed step between two cells: model.md section 3.10), a semi-implicit
 * Manning friction, and velocities desingularised on thin films (Kurganov & Petrova 2007).
 * State: depth h (m) and the unit discharges q_x (eastwards), q_y (northwards) (m^2/s). Each
 * cell computes the four faces around it (every face twice over the grid, by the same function
 * with the same arguments, so both sides see the same bits) and writes its outflows (m^3/s,
 * the other schemes' `flux_*`: the water update, the ledger and sediment transport take them
 * unchanged) and its new unit discharges. */
#ifndef ERODEM_KERNELS_COMMON_SHALLOW_WATER_H
#define ERODEM_KERNELS_COMMON_SHALLOW_WATER_H

#include "water.h"

ERODEM_BEGIN_NAMESPACE

/* The velocity (m/s) of unit discharge q (m^2/s) over depth h (m), desingularised below
 * h_eps (m) (Kurganov & Petrova 2007): 2 h q / (h^2 + max(h^2, h_eps^2)); q / h above h_eps, 0
 * on a dry cell, and bounded by q / h_eps on a film. */
ERODEM_FN_INLINED real sw_velocity(real q, real h, real h_eps) {
  const real h2 = h * h, e2 = h_eps * h_eps;
  const real den = h2 + (h2 > e2 ? h2 : e2);
  const real v = (real)2 * h * q / (den > (real)0 ? den : (real)1);
  return den > (real)0 ? v : (real)0;
}

/* HLLC flux (Toro 2001, sections 10.3-10.5) across a face between the states (h_l, u_l,
 * t_l) and (h_r, u_r, t_r): depths (m) reconstructed at the face, velocities normal to it
 * (positive from l to r) and along it (m/s); gravity g (m/s^2). Returns the mass flux (m^2/s)
 * and writes the flux of the normal momentum (m^3/s^2, with the pressure g h^2 / 2) through
 * *f_n and of the tangential momentum through *f_t (the mass flux carrying t of the side the
 * contact wave comes from). Wave speeds of Toro (2001, eq. 10.48): Einfeldt-type where both
 * sides are wet, the dry-front speeds u -+ 2c where one is dry; no flux between two dry
 * sides; two equal states give their physical flux exactly (a lake at rest stays at rest). */
ERODEM_FN_INLINED real sw_hllc(real h_l, real u_l, real t_l, real h_r, real u_r, real t_r, real g,
                               real* f_n, real* f_t) {
  /* Branch-free (selects only), so loops over cells vectorise; two dry sides give 0 through
   * the same arithmetic (all speeds u_r, every flux 0). */
  const int wet_l = h_l > (real)0, wet_r = h_r > (real)0;
  const real c_l = sqrt(g * h_l), c_r = sqrt(g * h_r);
  const real q_l = h_l * u_l, q_r = h_r * u_r;
  const real m_l = q_l * u_l + (real)0.5 * g * h_l * h_l;
  const real m_r = q_r * u_r + (real)0.5 * g * h_r * h_r;
  const real u_star = (real)0.5 * (u_l + u_r) + c_l - c_r;
  const real c_star = (real)0.5 * (c_l + c_r) + (real)0.25 * (u_l - u_r);
  const real s_l =
      wet_l ? (wet_r ? erodem_min(u_l - c_l, u_star - c_star) : u_l - c_l) : u_r - (real)2 * c_r;
  const real s_r =
      wet_l ? (wet_r ? erodem_max(u_r + c_r, u_star + c_star) : u_l + (real)2 * c_l) : u_r + c_r;
  const real span = s_r - s_l;
  const real inv = (real)1 / (span > (real)0 ? span : (real)1);
  const real h_hll = (s_r * q_l - s_l * q_r + s_l * s_r * (h_r - h_l)) * inv;
  const real m_hll = (s_r * m_l - s_l * m_r + s_l * s_r * (q_r - q_l)) * inv;
  const int same = (h_l == h_r) & (u_l == u_r) & (t_l == t_r);
  const real f_h = (same | (s_l >= (real)0)) ? q_l : (s_r <= (real)0 ? q_r : h_hll);
  const real f_m = (same | (s_l >= (real)0)) ? m_l : (s_r <= (real)0 ? m_r : m_hll);
  /* the contact wave's speed (Toro 2001, eq. 10.71); where its denominator vanishes the mass
   * flux's direction picks the side */
  const real den = h_r * (u_r - s_r) - h_l * (u_l - s_l);
  const real num = s_l * h_r * (u_r - s_r) - s_r * h_l * (u_l - s_l);
  const real s_star = den != (real)0 ? num / (den != (real)0 ? den : (real)1) : f_h;
  *f_n = f_m;
  *f_t = f_h * (s_star >= (real)0 ? t_l : t_r);
  return f_h;
}

/* What a face gives the two cells beside it (sw_face): a west or north of the face, b east or
 * south of it. */
ERODEM_STRUCT_BEGIN(SwFace)
  real mass;    /* mass flux (m^2/s, positive from a to b) */
  real mom_a;   /* normal momentum flux leaving a (m^3/s^2, positive from a to b) */
  real mom_b;   /* normal momentum flux entering b (equal to mom_a where the water meets) */
  real mom_t;   /* tangential momentum flux (m^3/s^2; the same for both sides) */
  real h_a;     /* a's depth at the face (m) */
  real h_b;     /* b's depth at the face (m) */
  real z;       /* the face bed (m) */
  real mom_low; /* a step's low side: its normal momentum flux against the step */
  real z_mean;  /* the mean of the two beds (m) */
  int step;     /* a step: 1 where a is the high side, -1 where b is, 0 where the water meets */
ERODEM_STRUCT_END(SwFace)

/* The face between padded cells a (west or north of it) and b (east or south), the normal
 * from a to b: kinds k_a, k_b; each side's depth h (m), bed z (m), velocity u normal to the
 * face (positive from a to b) and t along it (m/s); gravity g (m/s^2); eps (m) the depth below
 * which a side is dry. A ghost side takes the state its kind gives it (model.md section 3.10):
 * a wall mirrors the other side (the normal velocity reversed: no mass crosses), an open edge
 * copies its depth and velocity without any inflow over the ghost's own bed, which the boundary
 * process lowers by one cell of the local slope (a free outflow that continues the slope: on a
 * plane the last cell's film spills as every other does), a fixed level is still water: its
 * own depth and bed (set by the boundary process: its surface at the level) at rest, so the
 * Riemann problem with the active side gives the inflow or outflow the level drives.
 *
 * A face where the water meets: the reconstruction of Chen & Noelle (2017), the face bed
 *   z_f = min(max(z_a, z_b), min(eta_a, eta_b)),  eta = z + h,
 * each side's depth at the face h' = max(0, min(eta - z_f, h)), and the HLLC flux between
 * them, the same for both sides (well balanced: a lake at rest, wet or against a dry bank,
 * stays at rest).
 *
 * A step (model.md section 3.10): the high side is wet and the low side's surface lies at or
 * below the high side's bed, a film spilling down a bed step. The reconstruction would see
 * the low side as dry there, and the dry-bed Riemann problem's flux is a weir's, h (u + 2c) / 3,
 * which does not depend on the slope: rain on a steep plane ran off at a tenth of Manning's
 * speed. Here the film leaves with its own discharge instead, h max(u, 0) towards the step
 * (it is accelerated by the bed-slope source, which then sees the whole step: face bed the
 * mean of the two beds, each side's own depth), with its momentum h u^2 + g h^2 / 2; the low
 * side receives that discharge and momentum flux of the jet and the pressure of its own water
 * against the step, g h_low^2 / 2, or a wall's reflection where it runs towards the step. Mass
 * is conserved (one mass flux); momentum is not, as the step takes the force.
 *
 * Returns the face's fluxes, the two sides' depths at it and its bed for the bed-slope source,
 * and for a step which side is high, the low side's flux against it and the mean bed (SwFace).
 * No flux between two ghosts. Branch-free. */
ERODEM_FN_INLINED ERODEM_S(SwFace)
    sw_face(int k_a, int k_b, real h_a, real z_a, real u_a, real t_a, real h_b, real z_b, real u_b,
            real t_b, real g, real eps) {
  /* the ghost side's state selected, both sides computed, a face between two ghosts masked to
   * 0 at the end */
  const int active_a = k_a == ERODEM_CELL_ACTIVE, active_b = k_b == ERODEM_CELL_ACTIVE;
  const int ghost_b = active_a & !active_b, ghost_a = active_b & !active_a;
  const int fixed_b = k_b == ERODEM_CELL_FIXED, fixed_a = k_a == ERODEM_CELL_FIXED;
  const int wall_b = k_b == ERODEM_CELL_WALL, wall_a = k_a == ERODEM_CELL_WALL;
  const real hb0 = h_b, zb0 = z_b, ub0 = u_b, tb0 = t_b;
  h_b = ghost_b & !fixed_b ? h_a : hb0;
  z_b = ghost_b & wall_b ? z_a : zb0;
  u_b = ghost_b ? (fixed_b ? (real)0 : wall_b ? -u_a : (u_a > (real)0 ? u_a : (real)0)) : ub0;
  t_b = ghost_b ? (fixed_b ? (real)0 : t_a) : tb0;
  const real ha0 = h_a, za0 = z_a, ua0 = u_a, ta0 = t_a;
  h_a = ghost_a & !fixed_a ? hb0 : ha0;
  z_a = ghost_a & wall_a ? zb0 : za0;
  u_a = ghost_a ? (fixed_a ? (real)0 : wall_a ? -ub0 : (ub0 < (real)0 ? ub0 : (real)0)) : ua0;
  t_a = ghost_a ? (fixed_a ? (real)0 : tb0) : ta0;
  const int any = active_a | active_b;
  const real eta_a = z_a + h_a, eta_b = z_b + h_b;
  /* where the water meets: Chen & Noelle */
  const real z_hi = z_a > z_b ? z_a : z_b, eta_lo = eta_a < eta_b ? eta_a : eta_b;
  const real zf = z_hi < eta_lo ? z_hi : eta_lo;
  const real ra = eta_a - zf < h_a ? eta_a - zf : h_a;
  const real rb = eta_b - zf < h_b ? eta_b - zf : h_b;
  const real ha_f = any & (ra > (real)0) ? ra : (real)0;
  const real hb_f = any & (rb > (real)0) ? rb : (real)0;
  real fn, ft;
  const real fh = sw_hllc(ha_f, u_a, t_a, hb_f, u_b, t_b, g, &fn, &ft);
  /* a step: a film on the high side spilling onto the low side */
  const int a_high = z_a > z_b, b_high = z_b > z_a;
  const int step =
      any & ((a_high & (h_a > eps) & (eta_b <= z_a)) | (b_high & (h_b > eps) & (eta_a <= z_b)));
  const real h_hi = a_high ? h_a : h_b, h_lo = a_high ? h_b : h_a;
  const real t_hi = a_high ? t_a : t_b;
  /* the high side's velocity towards the step, and the low side's away from it */
  const real u_hi = a_high ? u_a : -u_b, u_lo = a_high ? u_b : -u_a;
  const real u_out = u_hi > (real)0 ? u_hi : (real)0;
  const real q_out = h_hi * u_out; /* the film's discharge over the step (m^2/s) */
  const real p_hi = (real)0.5 * g * h_hi * h_hi, p_lo = (real)0.5 * g * h_lo * h_lo;
  /* the low side against the step: its pressure, or where it runs towards the step at w > 0 a
   * wall's reflection, the HLLC flux of the mirrored states (h, w | h, -w): with the wave
   * speeds -+(c + w/2) it is g h^2 / 2 + h w^2 + (c + w/2) h w */
  const real w = u_lo < (real)0 ? -u_lo : (real)0;
  const real m_lo = p_lo + h_lo * w * (w + sqrt(g * h_lo) + (real)0.5 * w);
  const real jet = q_out * u_out; /* the momentum flux of the spilling film */
  /* in the face's orientation (positive from a to b): the mass and the normal momentum change
   * sign where b is the high side; the pressure terms do not */
  const real s = a_high ? (real)1 : (real)-1;
  const real fh_step = s * q_out;
  const real fn_hi = jet + p_hi, fn_lo = jet + m_lo;
  const real ft_step = s * q_out * t_hi;
  /* the low side: the jet, and a wall where it runs at the bank (below); its depth at the face
   * and the face bed stay Chen & Noelle's, so a pool below a wetted step stays at rest */
  const int bank_a = active_a & (h_a > eps) & (eta_a <= z_b);
  const int bank_b = active_b & (h_b > eps) & (eta_b <= z_a);
  const real w_a = u_a > (real)0 ? u_a : (real)0, w_b = u_b < (real)0 ? -u_b : (real)0;
  const real dyn_a = bank_a ? h_a * w_a * (sqrt(g * h_a) + (real)1.5 * w_a) : (real)0;
  const real dyn_b = bank_b ? h_b * w_b * (sqrt(g * h_b) + (real)1.5 * w_b) : (real)0;
  ERODEM_S(SwFace) r;
  r.mass = step ? fh_step : fh;
  r.mom_a = step ? (a_high ? fn_hi : jet + dyn_a) : fn + dyn_a;
  r.mom_b = step ? (a_high ? jet + dyn_b : fn_hi) : fn + dyn_b;
  r.mom_t = step ? ft_step : ft;
  r.h_a = ha_f;
  r.h_b = hb_f;
  r.z = zf;
  /* for a cell on a staircase (shallow_water_cell_update): which side is high, the low side's
   * momentum flux against the step (the jet and its own pressure, or a wall's reflection), and
   * the mean of the two beds */
  r.step = step ? (a_high ? 1 : -1) : 0;
  r.mom_low = fn_lo;
  r.z_mean = (real)0.5 * (z_a + z_b);
  return r;
}

/* What the shallow-water step gives a cell: its outflows (m^3/s) and unit discharges (m^2/s). */
ERODEM_STRUCT_BEGIN(SwCell)
  real left, right, top, bottom; /* outflows through the west, east, north and south faces */
  real q_x, q_y;                 /* the new unit discharges, eastwards and northwards */
ERODEM_STRUCT_END(SwCell)

/* The shallow-water step of a padded cell of kind k from its four faces (sw_face: e the face east
 * of it, where it is a; w west, where it is b; s south, where it is a; n north, where it is b;
 * the y-faces' normal pointing south), its state at the start of the step: depth h (m), unit
 * discharges q_x (east), q_y (north) (m^2/s), Manning n (s m^-1/3); the lengths of its x-faces
 * l_x and of its north and south faces l_n, l_s (m), its area a (m^2); dt (s); p.gravity (m/s^2)
 * and p.dry_depth (m: a cell left shallower has no discharge). Its outflows: an active cell's
 * scaled like the other schemes' so it gives no more than it holds; a fixed-level ghost gives to
 * its active neighbours (sw_face gives no flux between ghosts); other ghosts give nothing. An
 * active cell's new unit discharges:
 *
 *   q' = q - dt / a (sum over faces of L F_q - S),  then  q'' = q' - dt g n^2 |q''| q'' / h'^(7/3)
 *
 * with the bed-slope source of Chen & Noelle (2017) on the reconstructed depths of the cell's
 * sides of its faces, S_x = -g (h_E + h_W) / 2 (z_E - z_W) L_x, and in y the same over the
 * mean face length plus the pressure on the cell's sides where the north and south faces
 * differ in length (geographic grids), -g (h_N^2 + h_S^2) / 4 (L_S - L_N) (model.md section
 * 3.10: together they balance the fluxes of a lake at rest exactly); h' the depth after the
 * fluxes. Other cells keep their discharges. */
ERODEM_FN_INLINED ERODEM_S(SwCell)
    shallow_water_cell_update(int k, real h, real q_x, real q_y, real n, real l_x, real l_n,
                              real l_s, real a, real dt, ERODEM_P(FlowParams) p, ERODEM_S(SwFace) e,
                              ERODEM_S(SwFace) w, ERODEM_S(SwFace) s, ERODEM_S(SwFace) nf) {
  /* branch-free: everything computed for every cell, the results selected by its kind */
  const real g = p.gravity, eps = p.dry_depth;
  const int active = k == ERODEM_CELL_ACTIVE, gives = active | (k == ERODEM_CELL_FIXED);
  /* outflows: what leaves through each face (m^3/s) */
  const real o_r = (e.mass > (real)0 ? e.mass : (real)0) * l_x;
  const real o_l = (w.mass < (real)0 ? -w.mass : (real)0) * l_x;
  const real o_b = (s.mass > (real)0 ? s.mass : (real)0) * l_s;
  const real o_t = (nf.mass < (real)0 ? -nf.mass : (real)0) * l_n;
  const real K = active ? outflow_limit(h, a, o_l + o_r + o_t + o_b, dt) : (real)1;
  ERODEM_S(SwCell) out;
  out.left = gives ? o_l * K : (real)0;
  out.right = gives ? o_r * K : (real)0;
  out.top = gives ? o_t * K : (real)0;
  out.bottom = gives ? o_b * K : (real)0;
  /* A cell on a staircase, a film that a step drops onto and that drops over the next one in
   * the same direction (its uphill face a step with it low, its downhill one with it high):
   * the film on a slope, not a pool below a wall. Its bed-slope source takes its own depth at
   * both faces and the mean beds as the face beds, so it feels the whole g h S of the ramp the
   * steps stand for, and its uphill face pushes with its own pressure (balancing the downhill
   * face's); elsewhere Chen & Noelle's values (half of it on such a step, and a pool below a
   * step stays at rest). */
  const int stair_x = ((e.step == 1) & (w.step == 1)) | ((e.step == -1) & (w.step == -1));
  const int stair_y = ((s.step == 1) & (nf.step == 1)) | ((s.step == -1) & (nf.step == -1));
  /* each face's normal momentum flux on this cell's side (leaving it at its east and south
   * faces, entering it at its west and north faces), or on a staircase the low side's against
   * the step: at the east and south faces the cell is a, low where b is high (-1); at the west
   * and north faces it is b, low where a is high (+1) */
  const real fne = stair_x & (e.step == -1) ? e.mom_low : e.mom_a;
  const real fnw = stair_x & (w.step == 1) ? w.mom_low : w.mom_b;
  const real fns = stair_y & (s.step == -1) ? s.mom_low : s.mom_a;
  const real fnn = stair_y & (nf.step == 1) ? nf.mom_low : nf.mom_b;
  const real hE = stair_x ? h : e.h_a, hW = stair_x ? h : w.h_b;
  const real hS = stair_y ? h : s.h_a, hN = stair_y ? h : nf.h_b;
  const real zE = stair_x ? e.z_mean : e.z, zW = stair_x ? w.z_mean : w.z;
  const real zS = stair_y ? s.z_mean : s.z, zN = stair_y ? nf.z_mean : nf.z;
  /* the outward fluxes of q_x and of q_y (north) through the four faces (m^4/s^2): a y-face's
   * normal momentum is southward, so q_y takes its negative */
  const real phi_x = (fne - fnw) * l_x + s.mom_t * l_s - nf.mom_t * l_n;
  const real phi_y = (e.mom_t - w.mom_t) * l_x - fns * l_s + fnn * l_n;
  /* the bed-slope and side-pressure sources (m^4/s^2) on this cell's reconstructed depths */
  const real l_mean = (real)0.5 * (l_n + l_s);
  const real s_x = -g * (real)0.5 * (hE + hW) * (zE - zW) * l_x;
  const real s_y = -g * (real)0.5 * (hN + hS) * (zN - zS) * l_mean -
                   g * (real)0.25 * (hS * hS + hN * hN) * (l_s - l_n);
  const real qx1 = q_x - dt / a * (phi_x - s_x);
  const real qy1 = q_y - dt / a * (phi_y - s_y);
  /* the depth after the fluxes (this cell's mass balance) for the friction */
  const real mass = (e.mass - w.mass) * l_x + s.mass * l_s - nf.mass * l_n;
  const real h1 = h - dt / a * mass;
  const real h_f = h1 > eps ? h1 : eps;
  const real q_mag = sqrt(qx1 * qx1 + qy1 * qy1);
  const real h_7_3 = h_f * h_f * erodem_cbrt_positive(h_f);
  /* implicit in |q|: q = q' - dt k |q| q with k = g n^2 / h'^(7/3) is the root of
   * dt k |q|^2 + |q| - |q'| = 0, |q| = 2 |q'| / (1 + sqrt(1 + 4 dt k |q'|)): no overshoot, and
   * its fixed point is Manning's discharge whatever dt (the semi-implicit q' / (1 + dt k |q'|)
   * caps |q| at 1 / (dt k): a film of 2 mm on a slope of 0.3 at a tenth of Manning's speed) */
  const real dtk = dt * g * n * n / h_7_3;
  const real factor = (real)2 / ((real)1 + sqrt((real)1 + (real)4 * dtk * q_mag));
  const int wet = h1 > eps;
  out.q_x = active ? (wet ? qx1 * factor : (real)0) : q_x;
  out.q_y = active ? (wet ? qy1 * factor : (real)0) : q_y;
  return out;
}

/* Stores a stage's results for padded cell i: as they are (combine 0), or averaged with what
 * the arrays hold (combine 1: the first stage's outflows, the unit discharges at the start of the
 * step), Heun's second stage. */
ERODEM_FN void shallow_water_stage_store(int i, int combine, ERODEM_S(SwCell) r,
                                         GLOBAL real* out_left, GLOBAL real* out_right,
                                         GLOBAL real* out_top, GLOBAL real* out_bottom,
                                         GLOBAL real* q_x_new, GLOBAL real* q_y_new) {
  /* every value loaded, then selected: loaded under `combine`, PoCL's vectorised loop stored
   * all six through masks (tests/pocl_vectorisation.sh) */
  const real h = (real)0.5;
  const real l = out_left[i], rt = out_right[i], t = out_top[i], b = out_bottom[i];
  const real qx = q_x_new[i], qy = q_y_new[i];
  out_left[i] = combine ? h * (l + r.left) : r.left;
  out_right[i] = combine ? h * (rt + r.right) : r.right;
  out_top[i] = combine ? h * (t + r.top) : r.top;
  out_bottom[i] = combine ? h * (b + r.bottom) : r.bottom;
  q_x_new[i] = combine ? h * (qx + r.q_x) : r.q_x;
  q_y_new[i] = combine ? h * (qy + r.q_y) : r.q_y;
}

/* The rows of the faces north and south of padded row y (the faces between rows y_n and
 * y_n + 1, y_s and y_s + 1), for their widths: beyond the raster the nearest face's. */
ERODEM_INLINE int sw_north_face_row(int y) {
  return y >= 1 ? y - 1 : y;
}
ERODEM_INLINE int sw_south_face_row(int y, int H) {
  return y + 1 < H ? y : (y >= 1 ? y - 1 : y);
}

/* The shallow-water step of padded cell i of row y (shallow_water_cell_update), its neighbours'
 * kinds k_* and indices i_* (west, east, north, south) and the rows y_n, y_s of its north and
 * south faces (the faces between rows y_n and y_n + 1, y_s and y_s + 1), from the state at the
 * start of the step: depth, bed, unit discharges q_x (east), q_y (north) (m^2/s), and the
 * velocities (m/s, eastwards u and northwards v: sw_velocity with h_eps = p.dry_depth) of the
 * cell (u, v) and of its four neighbours (u_w, v_w ... u_s, v_s); Manning n (s m^-1/3; the cell's
 * at index i_manning: param_index), the rows' dx, dy (m) and cell areas (m^2); dt (s); p.gravity
 * (m/s^2) and p.dry_depth (m). Writes the cell's outflows (m^3/s) and unit discharges into the
 * second buffers. Each cell computes the four faces around it (every face twice over the grid, by
 * the same function with the same arguments, so both sides see the same bits; the CPU loop
 * computes each once, with those arguments). Written through shallow_water_stage_store, as a
 * first stage. */
ERODEM_FN_INLINED void shallow_water_cell_uv(
    int i, int y, int k_w, int k_e, int k_n, int k_s, int i_w, int i_e, int i_n, int i_s, int y_n,
    int y_s, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed, GLOBAL const real* depth,
    GLOBAL const real* q_x, GLOBAL const real* q_y, real u, real v, real u_w, real v_w, real u_e,
    real v_e, real u_n, real v_n, real u_s, real v_s, GLOBAL const real* manning, int i_manning,
    GLOBAL const real* dx, GLOBAL const real* dy, GLOBAL const real* area, real dt,
    ERODEM_P(FlowParams) p, GLOBAL real* out_left, GLOBAL real* out_right, GLOBAL real* out_top,
    GLOBAL real* out_bottom, GLOBAL real* q_x_new, GLOBAL real* q_y_new) {
  const int k = kind[i];
  const real g = p.gravity, eps = p.dry_depth;
  const real h = depth[i], z = bed[i];
  /* east face: a = this cell, b = east; normal east, tangent north */
  const ERODEM_S(SwFace) e = sw_face(k, k_e, h, z, u, v, depth[i_e], bed[i_e], u_e, v_e, g, eps);
  /* west face: a = west, b = this cell */
  const ERODEM_S(SwFace) w = sw_face(k_w, k, depth[i_w], bed[i_w], u_w, v_w, h, z, u, v, g, eps);
  /* south face: a = this cell, b = south; normal south (velocity -v), tangent east (u) */
  const ERODEM_S(SwFace) s = sw_face(k, k_s, h, z, -v, u, depth[i_s], bed[i_s], -v_s, u_s, g, eps);
  /* north face: a = north, b = this cell */
  const ERODEM_S(SwFace) nf = sw_face(k_n, k, depth[i_n], bed[i_n], -v_n, u_n, h, z, -v, u, g, eps);
  /* face lengths: x-faces the row's dy; y-faces the mean dx of their two rows */
  const ERODEM_S(SwCell) c = shallow_water_cell_update(
      k, h, q_x[i], q_y[i], manning[i_manning], dy[y], face_y_width(dx, y_n), face_y_width(dx, y_s),
      area[y], dt, p, e, w, s, nf);
  shallow_water_stage_store(i, 0, c, out_left, out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* ---- second order (flow.order = 2): MUSCL reconstruction and Heun's method ---------------- */

/* minmod(a, b): the one of a and b nearer 0 where they have the same sign, else 0 (either, the
 * same value, where they are equally near). With the same sign, a is nearer 0 where a < b for
 * positive a and a > b for negative a: one comparison of a with b, where |a| < |b| took two
 * absolute values that LLVM's SLP pass packed into a vector of two (sw_limited_slope). */
ERODEM_FN real sw_minmod(real a, real b) {
  const real m = (a > (real)0) == (a < b) ? a : b;
  return a * b > (real)0 ? m : (real)0;
}

/* The limited slope of a quantity of values f_m, f, f_p in three cells along a direction where
 * `on`: sw_minmod(f - f_m, f_p - f); else 0. Where f_m == f_p the two differences have opposite
 * signs (or are 0) and the slope is 0, so that case skips the minmod: the same values. Each
 * quantity's slope is computed in a block of its own, on a condition of its own: within one
 * block LLVM's SLP pass packs the four quantities' minmods into vectors of four, after which
 * PoCL cannot vectorise the loop over work-items ("instruction return type cannot be
 * vectorized", tests/pocl_vectorisation.sh); the loop vectoriser turns the blocks back into
 * selects. */
ERODEM_FN_INLINED real sw_limited_slope(int on, real f_m, real f, real f_p) {
  real s = (real)0;
  if (on & (f_m != f_p)) s = sw_minmod(f - f_m, f_p - f);
  return s;
}

/* A cell's limited slopes in one direction (the change per cell towards its next neighbour)
 * of its surface eta = z + h, depth h, the velocity normal to the faces u and along them t
 * (m/s); `on` 0 where the cell is reconstructed at first order. */
ERODEM_STRUCT_BEGIN(SwSlopes)
  real eta, h, u, t;
  int on;
ERODEM_STRUCT_END(SwSlopes)

/* The slopes of a cell (kind k, depth h, bed z, velocities u, t) from its previous (_m) and next
 * (_p) neighbours in one direction: minmod of the two one-sided differences (Van Leer's MUSCL
 * with the minmod limiter); none (first order) unless the three cells are active and wet (above
 * eps (m)): at edges, ghosts and shores the first-order faces stay, which keeps a lake at rest
 * against a dry bank at rest and every reconstructed depth positive (h +- s_h / 2 lies between
 * the cell's and a neighbour's depth). */
ERODEM_FN ERODEM_S(SwSlopes)
    sw_slopes(int k_m, int k, int k_p, real h_m, real h, real h_p, real z_m, real z, real z_p,
              real u_m, real u, real u_p, real t_m, real t, real t_p, real eps) {
  ERODEM_S(SwSlopes) s;
  s.on = (k_m == ERODEM_CELL_ACTIVE) & (k == ERODEM_CELL_ACTIVE) & (k_p == ERODEM_CELL_ACTIVE) &
         (h_m > eps) & (h > eps) & (h_p > eps);
  const real e_m = z_m + h_m, e = z + h, e_p = z_p + h_p;
  s.eta = sw_limited_slope(s.on, e_m, e, e_p);
  s.h = sw_limited_slope(s.on, h_m, h, h_p);
  s.u = sw_limited_slope(s.on, u_m, u, u_p);
  s.t = sw_limited_slope(s.on, t_m, t, t_p);
  return s;
}

/* A cell's state at one of its faces. */
ERODEM_STRUCT_BEGIN(SwSide)
  real h, z, u, t; /* depth (m), bed (m), velocities normal to and along the face (m/s) */
ERODEM_STRUCT_END(SwSide)

/* The state of a cell (depth h, bed z, velocities u, t) at its face half a cell along its slopes
 * s (d = 0.5 towards the next neighbour, -0.5 towards the previous): surface and depth
 * reconstructed, the bed their difference (so a lake at rest keeps a level surface), the
 * velocities reconstructed; the cell's own values where it has no slopes. */
ERODEM_FN ERODEM_S(SwSide) sw_side(real h, real z, real u, real t, ERODEM_S(SwSlopes) s, real d) {
  ERODEM_S(SwSide) r;
  const real h_f = h + d * s.h, eta_f = (z + h) + d * s.eta;
  r.h = s.on ? h_f : h;
  r.z = s.on ? eta_f - h_f : z;
  r.u = s.on ? u + d * s.u : u;
  r.t = s.on ? t + d * s.t : t;
  return r;
}

/* Heun's method (flow.order = 2): a first stage from the state at the start of the step (depth
 * h, unit discharges q) gives outflows o1 and unit discharges q1; the depth it leaves,
 * h1 = h + dt (inflow - outflow) / A (this function, for an active cell; other cells keep h), and
 * q1 give a second stage's o2 and q2; the step's outflows are (o1 + o2) / 2 and its unit
 * discharges (q + q2) / 2. The water update then takes the averaged outflows as from any
 * scheme: h' = h + dt (mean inflow - mean outflow) / A = (h + h2) / 2, Heun's depth, and
 * sediment moves with those mean fluxes. Each stage's outflows are limited to what the cell
 * holds at its start, so h' >= h / 2 >= 0. */
ERODEM_FN void shallow_water_stage_depth_cell(int x, int y, int W, int H,
                                              GLOBAL const erodem_kind_t* kind,
                                              GLOBAL const real* depth, GLOBAL const real* f_left,
                                              GLOBAL const real* f_right, GLOBAL const real* f_top,
                                              GLOBAL const real* f_bottom, GLOBAL const real* area,
                                              real dt, GLOBAL real* depth_stage) {
  const int i = x + y * W;
  const int inside = (x >= 1) & (x <= W - 2) & (y >= 1) & (y <= H - 2);
  /* active cells lie inside the halo; the others' neighbours are not read */
  const int active = inside & (kind[i] == ERODEM_CELL_ACTIVE);
  const int l = inside ? i - 1 : i, r = inside ? i + 1 : i;
  const int t = inside ? i - W : i, b = inside ? i + W : i;
  const real inflow = f_right[l] + f_left[r] + f_bottom[t] + f_top[b];
  const real outflow = f_left[i] + f_right[i] + f_top[i] + f_bottom[i];
  const real h1 = depth_after_fluxes(depth[i], inflow, outflow, dt, area[y]);
  depth_stage[i] = active ? (h1 > (real)0 ? h1 : (real)0) : depth[i];
}

/* One cell's state for the second-order faces: kind, depth (m), bed (m), velocities east and
 * north (m/s). */
ERODEM_STRUCT_BEGIN(SwCellState)
  real h, z, u, v;
  int k;
ERODEM_STRUCT_END(SwCellState)

/* The state of padded cell (x, y) (sw_velocity with h_eps = eps); outside the raster a wall
 * standing on the nearest cell's state (as shallow_water_cell clamps). */
ERODEM_FN ERODEM_S(SwCellState)
    sw_state_at(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                GLOBAL const real* bed, GLOBAL const real* depth, GLOBAL const real* q_x,
                GLOBAL const real* q_y, real eps) {
  const int xc = x < 0 ? 0 : (x >= W ? W - 1 : x), yc = y < 0 ? 0 : (y >= H ? H - 1 : y);
  const int i = xc + yc * W;
  ERODEM_S(SwCellState) c;
  c.k = kind_at(kind, x, y, W, H);
  c.h = depth[i];
  c.z = bed[i];
  c.u = sw_velocity(q_x[i], c.h, eps);
  c.v = sw_velocity(q_y[i], c.h, eps);
  return c;
}

/* x-direction slopes of cell c from its west (m) and east (p) neighbours: u normal, v along. */
ERODEM_FN ERODEM_S(SwSlopes) sw_slopes_x(ERODEM_S(SwCellState) m, ERODEM_S(SwCellState) c,
                                         ERODEM_S(SwCellState) p, real eps) {
  return sw_slopes(m.k, c.k, p.k, m.h, c.h, p.h, m.z, c.z, p.z, m.u, c.u, p.u, m.v, c.v, p.v, eps);
}

/* y-direction slopes of cell c from its north (m) and south (p) neighbours (towards the south:
 * rows grow southwards): v "normal", u along. */
ERODEM_FN ERODEM_S(SwSlopes) sw_slopes_y(ERODEM_S(SwCellState) m, ERODEM_S(SwCellState) c,
                                         ERODEM_S(SwCellState) p, real eps) {
  return sw_slopes(m.k, c.k, p.k, m.h, c.h, p.h, m.z, c.z, p.z, m.v, c.v, p.v, m.u, c.u, p.u, eps);
}

/* The x-face between cells a (west) and b (east) with their x-slopes (sw_face on the
 * reconstructed sides). */
ERODEM_FN_INLINED ERODEM_S(SwFace)
    sw_face_x2(ERODEM_S(SwCellState) a, ERODEM_S(SwSlopes) sa, ERODEM_S(SwCellState) b,
               ERODEM_S(SwSlopes) sb, real g, real eps) {
  const ERODEM_S(SwSide) l = sw_side(a.h, a.z, a.u, a.v, sa, (real)0.5);
  const ERODEM_S(SwSide) r = sw_side(b.h, b.z, b.u, b.v, sb, (real)-0.5);
  return sw_face(a.k, b.k, l.h, l.z, l.u, l.t, r.h, r.z, r.u, r.t, g, eps);
}

/* The y-face between cells a (north) and b (south) with their y-slopes: normal southwards
 * (the velocity -v), tangent east (u). */
ERODEM_FN_INLINED ERODEM_S(SwFace)
    sw_face_y2(ERODEM_S(SwCellState) a, ERODEM_S(SwSlopes) sa, ERODEM_S(SwCellState) b,
               ERODEM_S(SwSlopes) sb, real g, real eps) {
  const ERODEM_S(SwSide) l = sw_side(a.h, a.z, a.v, a.u, sa, (real)0.5);
  const ERODEM_S(SwSide) r = sw_side(b.h, b.z, b.v, b.u, sb, (real)-0.5);
  return sw_face(a.k, b.k, l.h, l.z, -l.u, l.t, r.h, r.z, -r.u, r.t, g, eps);
}

/* A stage of the second-order step of padded cell i of row y (0 <= y < H) from the states of the
 * cells around it (SwCellState: c the cell, w1, w2 one and two cells west, e1, e2 east, n1, n2
 * north, s1, s2 south): its four faces from their MUSCL-reconstructed sides, then
 * shallow_water_cell_update on the stage's depth and unit discharges (c.h; q_x, q_y at i). The
 * first stage (combine 0) writes the outflows and unit discharges as the first-order step does;
 * the second (combine 1) writes the step's: the mean of the first stage's outflows (read from
 * out_*, where it left them) and its own, and the mean of the unit discharges at the start of
 * the step (q_x_new, q_y_new on entry) and its own. Manning's n at index i_manning
 * (param_index). */
ERODEM_FN_INLINED void shallow_water_muscl_cell_states(
    int i, int y, int H, ERODEM_S(SwCellState) c, ERODEM_S(SwCellState) w1,
    ERODEM_S(SwCellState) w2, ERODEM_S(SwCellState) e1, ERODEM_S(SwCellState) e2,
    ERODEM_S(SwCellState) n1, ERODEM_S(SwCellState) n2, ERODEM_S(SwCellState) s1,
    ERODEM_S(SwCellState) s2, GLOBAL const real* q_x, GLOBAL const real* q_y,
    GLOBAL const real* manning, int i_manning, GLOBAL const real* dx, GLOBAL const real* dy,
    GLOBAL const real* area, real dt, ERODEM_P(FlowParams) p, int combine, GLOBAL real* out_left,
    GLOBAL real* out_right, GLOBAL real* out_top, GLOBAL real* out_bottom, GLOBAL real* q_x_new,
    GLOBAL real* q_y_new) {
  const real g = p.gravity, eps = p.dry_depth;
  const ERODEM_S(SwSlopes) sx_c = sw_slopes_x(w1, c, e1, eps);
  const ERODEM_S(SwSlopes) sy_c = sw_slopes_y(n1, c, s1, eps);
  const ERODEM_S(SwFace) fe = sw_face_x2(c, sx_c, e1, sw_slopes_x(c, e1, e2, eps), g, eps);
  const ERODEM_S(SwFace) fw = sw_face_x2(w1, sw_slopes_x(w2, w1, c, eps), c, sx_c, g, eps);
  const ERODEM_S(SwFace) fs = sw_face_y2(c, sy_c, s1, sw_slopes_y(c, s1, s2, eps), g, eps);
  const ERODEM_S(SwFace) fn = sw_face_y2(n1, sw_slopes_y(n2, n1, c, eps), c, sy_c, g, eps);
  const int y_n = sw_north_face_row(y), y_s = sw_south_face_row(y, H);
  const ERODEM_S(SwCell) r = shallow_water_cell_update(
      c.k, c.h, q_x[i], q_y[i], manning[i_manning], dy[y], face_y_width(dx, y_n),
      face_y_width(dx, y_s), area[y], dt, p, fe, fw, fs, fn);
  shallow_water_stage_store(i, combine, r, out_left, out_right, out_top, out_bottom, q_x_new,
                            q_y_new);
}

/* shallow_water_muscl_cell_states for padded cell (x, y) of any row 0 <= y < H: the cells'
 * states by sw_state_at (indices clamped into the raster, kinds outside it walls, velocities
 * computed here), and with boundary.periodic_x the cells two columns off wrapped around the
 * seam. */
ERODEM_FN_INLINED void shallow_water_muscl_cell(
    int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
    GLOBAL const real* depth, GLOBAL const real* q_x, GLOBAL const real* q_y,
    GLOBAL const real* manning, GLOBAL const real* dx, GLOBAL const real* dy,
    GLOBAL const real* area, real dt, ERODEM_P(FlowParams) p, int combine, GLOBAL real* out_left,
    GLOBAL real* out_right, GLOBAL real* out_top, GLOBAL real* out_bottom, GLOBAL real* q_x_new,
    GLOBAL real* q_y_new) {
  const real eps = p.dry_depth;
  const ERODEM_S(SwCellState) c = sw_state_at(x, y, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) w1 = sw_state_at(x - 1, y, W, H, kind, bed, depth, q_x, q_y, eps);
  /* with periodic_x the cells two columns off wrap around the seam (the ghost columns repeat
   * the opposite DEM columns, the cells beyond them lie inside the grid) */
  const int x_w2 = p.periodic_x && x - 2 < 1 ? x - 2 + (W - 2) : x - 2;
  const int x_e2 = p.periodic_x && x + 2 > W - 2 ? x + 2 - (W - 2) : x + 2;
  const ERODEM_S(SwCellState) w2 = sw_state_at(x_w2, y, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) e1 = sw_state_at(x + 1, y, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) e2 = sw_state_at(x_e2, y, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) n1 = sw_state_at(x, y - 1, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) n2 = sw_state_at(x, y - 2, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) s1 = sw_state_at(x, y + 1, W, H, kind, bed, depth, q_x, q_y, eps);
  const ERODEM_S(SwCellState) s2 = sw_state_at(x, y + 2, W, H, kind, bed, depth, q_x, q_y, eps);
  shallow_water_muscl_cell_states(x + y * W, y, H, c, w1, w2, e1, e2, n1, n2, s1, s2, q_x, q_y,
                                  manning, param_index(x, y, p.manning_pitch), dx, dy, area, dt, p,
                                  combine, out_left, out_right, out_top, out_bottom, q_x_new,
                                  q_y_new);
}

/* The state of padded cell i for the second-order faces from the velocities u, v (m/s) of every
 * cell (shallow_water_flow_velocity_cell: the same values sw_state_at computes). */
ERODEM_FN_INLINED ERODEM_S(SwCellState)
    sw_state_of(int i, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
                GLOBAL const real* depth, GLOBAL const real* u, GLOBAL const real* v) {
  ERODEM_S(SwCellState) c;
  c.k = kind[i];
  c.h = depth[i];
  c.z = bed[i];
  c.u = u[i];
  c.v = v[i];
  return c;
}

/* a where c, else b: each member selected. */
ERODEM_FN_INLINED ERODEM_S(SwCellState)
    sw_state_pick(int c, ERODEM_S(SwCellState) a, ERODEM_S(SwCellState) b) {
  ERODEM_S(SwCellState) r;
  r.k = c ? a.k : b.k;
  r.h = c ? a.h : b.h;
  r.z = c ? a.z : b.z;
  r.u = c ? a.u : b.u;
  r.v = c ? a.v : b.v;
  return r;
}

/* shallow_water_muscl_cell_states for padded cell (x, y) of a row 2 <= y <= H - 3, any
 * 0 <= x <= W - 1, with the velocities u, v of every cell
 * (shallow_water_flow_velocity_cell): the cells at i -+ 1, i -+ 2, i -+ W, i -+ 2 W without
 * clamping, their kinds as they are, so the loads of a row are consecutive (PoCL vectorises the
 * loop over x on CPU devices). The same results as shallow_water_muscl_cell: near the first and
 * last column, x -+ 1 and x -+ 2 reach across the row ends into the row above or below, where
 * shallow_water_muscl_cell clamps to the nearest cell as a wall. Without periodic_x the ghost
 * columns 0 and W - 1 are not active, so
 * - a cell two columns off enters only the slopes of a ghost (w2 those of w1 at x = 1, e2 those of
 *   e1 at x = W - 2; at x = 0 and W - 1 those of w1 or e1 beyond the ghost cell itself), and a
 *   ghost's slopes are 0 (sw_slopes: first order unless the three cells are active);
 * - a cell one column off across the row end meets a ghost (x = 0 or W - 1): a face between two
 *   ghosts carries nothing (sw_face), and a ghost's other results do not read it (its unit
 *   discharges are kept; it gives only through its faces with active cells).
 * With periodic_x the ghost columns are active copies of the opposite DEM columns (every
 * exchange copies them), which shallow_water_muscl_cell reads as they are too, but for the cell
 * two columns west of column 1 and east of column W - 2: it wraps them around the seam to
 * columns W - 3 and 2, and so does this function (loaded at those cells of the row, the same for
 * every work-item of a row, so no gather, and selected there). In the ghost columns themselves
 * the results differ, and the exchange after each stage overwrites them. */
ERODEM_FN_INLINED void shallow_water_muscl_cell_interior(
    int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
    GLOBAL const real* depth, GLOBAL const real* q_x, GLOBAL const real* q_y, GLOBAL const real* u,
    GLOBAL const real* v, GLOBAL const real* manning, GLOBAL const real* dx, GLOBAL const real* dy,
    GLOBAL const real* area, real dt, ERODEM_P(FlowParams) p, int combine, GLOBAL real* out_left,
    GLOBAL real* out_right, GLOBAL real* out_top, GLOBAL real* out_bottom, GLOBAL real* q_x_new,
    GLOBAL real* q_y_new) {
  const int i = x + y * W;
  const int periodic = p.periodic_x != 0;
  const int seam_w = periodic & (x == 1), seam_e = periodic & (x == W - 2);
  const ERODEM_S(SwCellState) w2 =
      sw_state_pick(seam_w, sw_state_of(y * W + W - 3, kind, bed, depth, u, v),
                    sw_state_of(i - 2, kind, bed, depth, u, v));
  const ERODEM_S(SwCellState) e2 =
      sw_state_pick(seam_e, sw_state_of(y * W + 2, kind, bed, depth, u, v),
                    sw_state_of(i + 2, kind, bed, depth, u, v));
  shallow_water_muscl_cell_states(
      i, y, H, sw_state_of(i, kind, bed, depth, u, v), sw_state_of(i - 1, kind, bed, depth, u, v),
      w2, sw_state_of(i + 1, kind, bed, depth, u, v), e2,
      sw_state_of(i - W, kind, bed, depth, u, v), sw_state_of(i - 2 * W, kind, bed, depth, u, v),
      sw_state_of(i + W, kind, bed, depth, u, v), sw_state_of(i + 2 * W, kind, bed, depth, u, v),
      q_x, q_y, manning, param_index(x, y, p.manning_pitch), dx, dy, area, dt, p, combine, out_left,
      out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* shallow_water_cell_uv for padded cell (x, y) of any row 0 <= y < H: the neighbours' indices
 * clamped into the raster, their kinds outside it walls, every velocity computed here. */
ERODEM_FN void shallow_water_cell(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL const real* bed, GLOBAL const real* depth,
                                  GLOBAL const real* q_x, GLOBAL const real* q_y,
                                  GLOBAL const real* manning, GLOBAL const real* dx,
                                  GLOBAL const real* dy, GLOBAL const real* area, real dt,
                                  ERODEM_P(FlowParams) p, GLOBAL real* out_left,
                                  GLOBAL real* out_right, GLOBAL real* out_top,
                                  GLOBAL real* out_bottom, GLOBAL real* q_x_new,
                                  GLOBAL real* q_y_new) {
  const int i = x + y * W;
  const int i_w = x >= 1 ? i - 1 : i, i_e = x + 1 < W ? i + 1 : i;
  const int i_n = y >= 1 ? i - W : i, i_s = y + 1 < H ? i + W : i;
  const real eps = p.dry_depth;
  shallow_water_cell_uv(
      i, y, kind_at(kind, x - 1, y, W, H), kind_at(kind, x + 1, y, W, H),
      kind_at(kind, x, y - 1, W, H), kind_at(kind, x, y + 1, W, H), i_w, i_e, i_n, i_s,
      sw_north_face_row(y), sw_south_face_row(y, H), kind, bed, depth, q_x, q_y,
      sw_velocity(q_x[i], depth[i], eps), sw_velocity(q_y[i], depth[i], eps),
      sw_velocity(q_x[i_w], depth[i_w], eps), sw_velocity(q_y[i_w], depth[i_w], eps),
      sw_velocity(q_x[i_e], depth[i_e], eps), sw_velocity(q_y[i_e], depth[i_e], eps),
      sw_velocity(q_x[i_n], depth[i_n], eps), sw_velocity(q_y[i_n], depth[i_n], eps),
      sw_velocity(q_x[i_s], depth[i_s], eps), sw_velocity(q_y[i_s], depth[i_s], eps), manning,
      param_index(x, y, p.manning_pitch), dx, dy, area, dt, p, out_left, out_right, out_top,
      out_bottom, q_x_new, q_y_new);
}

/* The velocities the shallow-water faces read, of padded cell (x, y): sw_velocity of its unit
 * discharges q_x, q_y (m^2/s) over its depth (m) with h_eps = dry_depth (m), into u, v (m/s),
 * every cell. For shallow_water_cell_interior and shallow_water_muscl_cell_interior, which then
 * read them instead of computing each cell's five times (nine at the second order: once as
 * itself, once as each neighbour's neighbour); the same values. */
ERODEM_FN void shallow_water_flow_velocity_cell(int x, int y, int W, GLOBAL const real* depth,
                                                GLOBAL const real* q_x, GLOBAL const real* q_y,
                                                real dry_depth, GLOBAL real* u, GLOBAL real* v) {
  const int i = x + y * W;
  const real h = depth[i], qx = q_x[i], qy = q_y[i];
  u[i] = sw_velocity(qx, h, dry_depth);
  v[i] = sw_velocity(qy, h, dry_depth);
}

/* shallow_water_cell_uv for padded cell (x, y) of a row 1 <= y <= H - 2, any 0 <= x <= W - 1,
 * with the velocities u, v of every cell (shallow_water_flow_velocity_cell): the neighbours at
 * i -+ 1 and i -+ W without clamping, their kinds as they are, so the loads of a row are
 * consecutive (PoCL vectorises the loop over x on CPU devices). In the first and last column
 * x - 1 and x + 1 reach across the row ends to the ghost column of the row above or below, where
 * shallow_water_cell clamps to the cell itself, a wall: a ghost cell's face with another ghost
 * carries nothing either way (sw_face: no flux between two ghosts), and a ghost's other results
 * do not read that face (its unit discharges are kept; it gives only through its faces with
 * active cells), so the results are the same. */
ERODEM_FN void shallow_water_cell_interior(
    int x, int y, int W, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
    GLOBAL const real* depth, GLOBAL const real* q_x, GLOBAL const real* q_y, GLOBAL const real* u,
    GLOBAL const real* v, GLOBAL const real* manning, GLOBAL const real* dx, GLOBAL const real* dy,
    GLOBAL const real* area, real dt, ERODEM_P(FlowParams) p, GLOBAL real* out_left,
    GLOBAL real* out_right, GLOBAL real* out_top, GLOBAL real* out_bottom, GLOBAL real* q_x_new,
    GLOBAL real* q_y_new) {
  const int i = x + y * W;
  shallow_water_cell_uv(i, y, kind[i - 1], kind[i + 1], kind[i - W], kind[i + W], i - 1, i + 1,
                        i - W, i + W, y - 1, y, kind, bed, depth, q_x, q_y, u[i], v[i], u[i - 1],
                        v[i - 1], u[i + 1], v[i + 1], u[i - W], v[i - W], u[i + W], v[i + W],
                        manning, param_index(x, y, p.manning_pitch), dx, dy, area, dt, p, out_left,
                        out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* The velocity of padded cell (x, y) from its unit discharges and its depth after the water
 * update: sw_velocity (eastwards and northwards, m/s) with h_eps the water update's
 * velocity_min_depth (m): the velocity the other processes, the statistics and the adaptive
 * step read. 0 on other cells. The generic sweep "shallow_water_velocity" of the water
 * process (kernels/cpu/sweeps.cpp, kernels/opencl/water.cl). */
ERODEM_FN void shallow_water_velocity_sweep_cell(int x, int y, int W,
                                                 GLOBAL const erodem_kind_t* kind,
                                                 GLOBAL const real* depth, GLOBAL const real* q_x,
                                                 GLOBAL const real* q_y, GLOBAL real* velocity_x,
                                                 GLOBAL real* velocity_y, GLOBAL const real* area,
                                                 real dt, ERODEM_P(WaterParams) p) {
  (void)area;
  (void)dt;
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  /* every load unconditional and the results selected: with the unit discharges loaded under
   * `active`, clang kept a branch around both velocities, LLVM's SLP pass paired them in a vector
   * of two at its end, and PoCL left the kernel scalar across work-items on AVX2 ("instruction
   * return type cannot be vectorized"; tests/pocl_vectorisation.sh) */
  const real h = depth[i], qx = q_x[i], qy = q_y[i];
  const real u = sw_velocity(qx, h, p.velocity_min_depth);
  const real v = sw_velocity(qy, h, p.velocity_min_depth);
  velocity_x[i] = active ? u : (real)0;
  velocity_y[i] = active ? v : (real)0;
}

ERODEM_END_NAMESPACE

#endif
