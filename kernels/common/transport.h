/* erodem — suspended-sediment transport (MODEL.md step 5), two schemes. */
#ifndef ERODEM_KERNELS_COMMON_TRANSPORT_H
#define ERODEM_KERNELS_COMMON_TRANSPORT_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Sediment carried per unit of water (m/m): suspended layer s over the water depth that the
 * flow step moved, 0 for a dry cell. */
ERODEM_FN real sediment_concentration(real sediment, real depth) {
  const int wet = depth > 0;
  const real c = sediment / (wet ? depth : (real)1);
  return wet ? c : (real)0;
}

/* Net sediment volume (m^3) that padded cell i carries out of the domain in dt (s): its
 * concentration times what flows through its faces to ghosts, less what the ghosts' water
 * brings in at theirs (fixed-level ghosts hold boundary.sediment_concentration of their depth;
 * others none). Only cells beside a ghost have one (the OpenCL backend sums it over a list of
 * them, kernels/opencl/edges.cl). */
ERODEM_FN real transport_boundary_out_cell(int i, int W, GLOBAL const erodem_kind_t* kind,
                                           GLOBAL const real* sediment,
                                           GLOBAL const real* depth_flow, GLOBAL const real* f_left,
                                           GLOBAL const real* f_right, GLOBAL const real* f_top,
                                           GLOBAL const real* f_bottom, real dt) {
  const real c = sediment_concentration(sediment[i], depth_flow[i]);
  /* faces with active neighbours add +0 (branch-free, the same sum as skipping them) */
  const real to_ghosts = (real)0 + (kind[i - 1] != ERODEM_CELL_ACTIVE ? f_left[i] : (real)0) +
                         (kind[i + 1] != ERODEM_CELL_ACTIVE ? f_right[i] : (real)0) +
                         (kind[i - W] != ERODEM_CELL_ACTIVE ? f_top[i] : (real)0) +
                         (kind[i + W] != ERODEM_CELL_ACTIVE ? f_bottom[i] : (real)0);
  const real from_ghosts =
      (real)0 +
      (kind[i - 1] != ERODEM_CELL_ACTIVE
           ? sediment_concentration(sediment[i - 1], depth_flow[i - 1]) * f_right[i - 1]
           : (real)0) +
      (kind[i + 1] != ERODEM_CELL_ACTIVE
           ? sediment_concentration(sediment[i + 1], depth_flow[i + 1]) * f_left[i + 1]
           : (real)0) +
      (kind[i - W] != ERODEM_CELL_ACTIVE
           ? sediment_concentration(sediment[i - W], depth_flow[i - W]) * f_bottom[i - W]
           : (real)0) +
      (kind[i + W] != ERODEM_CELL_ACTIVE
           ? sediment_concentration(sediment[i + W], depth_flow[i + W]) * f_top[i + W]
           : (real)0);
  return dt * c * to_ghosts - dt * from_ghosts;
}

/* Conservative (flux-form upwind) transport for active padded cell (x, y): sediment leaves
 * with the water that leaves, using the same pipe fluxes as the water update. `depth_flow`
 * is the depth the flow step limited its outflows by (before the water update), so a cell
 * never gives more sediment than it holds:
 *   s_i <- s_i + dt / area_i * (sum_n c_n f_{n->i} - c_i sum_n f_{i->n}),  c = s / d.
 * Returns the new sediment (m), through *boundary_out the volume (m^3) carried out of the
 * domain and through *given the volume (m^3) the cell gave through all its faces. Conserves
 * sum(s * area) to rounding. Branch-free. */
ERODEM_FN real transport_conservative_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                           GLOBAL const real* sediment,
                                           GLOBAL const real* depth_flow, GLOBAL const real* f_left,
                                           GLOBAL const real* f_right, GLOBAL const real* f_top,
                                           GLOBAL const real* f_bottom, GLOBAL const real* area,
                                           real dt, real* boundary_out, real* given_out) {
  const int i = x + y * W;
  const real c = sediment_concentration(sediment[i], depth_flow[i]);
  const real gained = sediment_concentration(sediment[i - 1], depth_flow[i - 1]) * f_right[i - 1] +
                      sediment_concentration(sediment[i + 1], depth_flow[i + 1]) * f_left[i + 1] +
                      sediment_concentration(sediment[i - W], depth_flow[i - W]) * f_bottom[i - W] +
                      sediment_concentration(sediment[i + W], depth_flow[i + W]) * f_top[i + W];
  const real given = c * (f_left[i] + f_right[i] + f_top[i] + f_bottom[i]);
  const real s_new = sediment[i] + dt * (gained - given) / area[y];
  *given_out = dt * given;
  *boundary_out = transport_boundary_out_cell(i, W, kind, sediment, depth_flow, f_left, f_right,
                                              f_top, f_bottom, dt);
  return s_new;
}

/* Semi-Lagrangian transport (Mei et al. 2007) for active padded cell (x, y):
 *   s(x) <- s(x - v dt), bilinear, the departure point clamped to the DEM.
 * Fast and not conservative: the caller measures the change of sum(s * area). Velocity
 * (m/s): velocity_x eastwards, velocity_y northwards (rows grow southwards). */
ERODEM_FN real transport_semi_lagrangian_cell(int x, int y, int W, int H,
                                              GLOBAL const real* sediment,
                                              GLOBAL const real* velocity_x,
                                              GLOBAL const real* velocity_y, GLOBAL const real* dx,
                                              GLOBAL const real* dy, real dt, int periodic_x) {
  const int i = x + y * W;
  real px = (real)x - velocity_x[i] * dt / dx[y];
  real py = (real)y + velocity_y[i] * dt / dy[y];
  /* with periodic_x the departure point may lie in the ghost columns, which repeat the
   * opposite DEM columns (it crosses the seam) */
  const int x_lo = periodic_x ? 0 : 1, x_hi = periodic_x ? W - 1 : W - 2;
  px = fmin(fmax(px, (real)x_lo), (real)x_hi);
  py = fmin(fmax(py, (real)1), (real)(H - 2));
  int x0 = (int)px;
  int y0 = (int)py;
  if (x0 > x_hi - 1) x0 = x_hi - 1;
  if (y0 > H - 3) y0 = H - 3;
  if (x0 < x_lo) x0 = x_lo;
  if (y0 < 1) y0 = 1;
  const real tx = px - (real)x0;
  const real ty = py - (real)y0;
  const int j = x0 + y0 * W;
  const real top = sediment[j] * ((real)1 - tx) + sediment[j + 1] * tx;
  const real bottom = sediment[j + W] * ((real)1 - tx) + sediment[j + W + 1] * tx;
  return top * ((real)1 - ty) + bottom * ty;
}

/* The conservative transport sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body
 * of both backends' loops (kernels/cpu/transport.cpp, kernels/opencl/transport.cl): active
 * cells (1 <= x <= W - 2, kind active) write their new sediment through *sediment_new (the
 * kernel stores it in a second buffer, the CPU loop in a row it writes back once no row reads
 * the old sediment there), others their old one. Writes through *carried the volume carried out of
 * the domain and through *given the volume the cell gave (m^3; 0 for others). Branch-free. */
ERODEM_FN void transport_conservative_sweep_cell(
    int x, int y, int W, GLOBAL const erodem_kind_t* kind, GLOBAL const real* sediment,
    GLOBAL const real* depth_flow, GLOBAL const real* f_left, GLOBAL const real* f_right,
    GLOBAL const real* f_top, GLOBAL const real* f_bottom, GLOBAL const real* area, real dt,
    real* sediment_new, real* carried, real* given) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  real gone, gave;
  const real s_new = transport_conservative_cell(x, y, W, kind, sediment, depth_flow, f_left,
                                                 f_right, f_top, f_bottom, area, dt, &gone, &gave);
  const real s_old = sediment[i]; /* an unconditional load: if-convertible */
  *sediment_new = active ? s_new : s_old;
  *carried = active ? gone : (real)0;
  *given = active ? gave : (real)0;
}

ERODEM_END_NAMESPACE

#endif
