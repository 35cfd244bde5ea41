/* erodem — flow: the four outflow pipes of every cell, two schemes behind one switch.
 * Written once for the CPU reference and the OpenCL kernels (see compat.h).
 *
 * Both schemes produce, for every cell, the outflow discharge through each of its four
 * faces, f >= 0 in m^3/s (`flux_left/right/top/bottom`). The signed discharge across the
 * face between cells a and b is f_towards_b(a) - f_towards_a(b); every face is computed
 * from the same arguments in the same order by the two cells beside it, so both see the
 * same number and no cell writes anything but its own fluxes (gather, no atomics).
 */
#ifndef ERODEM_KERNELS_COMMON_FLOW_H
#define ERODEM_KERNELS_COMMON_FLOW_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Kind of padded cell (x, y); anything outside the padded raster is a wall. */
ERODEM_INLINE int kind_at(GLOBAL const erodem_kind_t* kind, int x, int y, int W, int H) {
  return (x < 0 || y < 0 || x >= W || y >= H) ? ERODEM_CELL_WALL : (int)kind[x + y * W];
}

/* Whether a cell of kind `from` gives water to a neighbour of kind `to`. Active cells give
 * to anything but walls; fixed-level ghosts give to active cells; walls and open ghosts
 * give nothing. */
ERODEM_INLINE int gives_water(int from, int to) {
  if (from == ERODEM_CELL_ACTIVE) return to != ERODEM_CELL_WALL;
  if (from == ERODEM_CELL_FIXED) return to == ERODEM_CELL_ACTIVE;
  return 0;
}

/* Whether any water crosses the face between kinds a and b. */
ERODEM_INLINE int face_open(int a, int b) {
  return gives_water(a, b) || gives_water(b, a);
}

/* Scale factor K of Mei et al. (2007): a cell holding `depth` (m) over `cell_area` (m^2)
 * gives at most what it holds in one step of `dt` (s) at total outflow `total_out` (m^3/s). */
ERODEM_FN real outflow_limit(real depth, real cell_area, real total_out, real dt) {
  const real demand = total_out * dt;
  const real held = depth * cell_area;
  return demand > held ? held / demand : (real)1;
}

/* ---- pipes (Mei, Decaudin & Hu 2007) ------------------------------------------------ */

/* One pipe's outflow after a step: f <- max(0, f + dt * A * g * dh / l).
 * f (m^3/s), dt (s), pipe_area A (m^2), gravity g (m/s^2), dh surface drop towards the
 * neighbour (m), length l (m). */
ERODEM_FN real pipe_flux_update(real f, real dt, real pipe_area, real gravity, real dh,
                                real length) {
  return fmax((real)0, f + dt * pipe_area * gravity * dh / length);
}

/* Pipes scheme for padded cell (x, y): reads the previous fluxes f_*, writes out_*. */
ERODEM_FN void flow_pipes_cell(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                               GLOBAL const real* bed, GLOBAL const real* depth,
                               GLOBAL const real* dx, GLOBAL const real* dy,
                               GLOBAL const real* area, GLOBAL const real* f_left,
                               GLOBAL const real* f_right, GLOBAL const real* f_top,
                               GLOBAL const real* f_bottom, GLOBAL real* out_left,
                               GLOBAL real* out_right, GLOBAL real* out_top,
                               GLOBAL real* out_bottom, real dt, real gravity, real pipe_area,
                               real pipe_length) {
  const int i = x + y * W;
  const int k = kind[i];
  real fl = 0, fr = 0, ft = 0, fb = 0;
  if (k == ERODEM_CELL_ACTIVE || k == ERODEM_CELL_FIXED) {
    const real eta = bed[i] + depth[i];
    /* pipe lengths: the distance between cell centres unless a length is given */
    const real lx = pipe_length > 0 ? pipe_length : dx[y];
    if (gives_water(k, kind_at(kind, x - 1, y, W, H)))
      fl = pipe_flux_update(f_left[i], dt, pipe_area, gravity, eta - (bed[i - 1] + depth[i - 1]),
                            lx);
    if (gives_water(k, kind_at(kind, x + 1, y, W, H)))
      fr = pipe_flux_update(f_right[i], dt, pipe_area, gravity, eta - (bed[i + 1] + depth[i + 1]),
                            lx);
    if (gives_water(k, kind_at(kind, x, y - 1, W, H))) {
      const real l = pipe_length > 0 ? pipe_length : (real)0.5 * (dy[y] + dy[y - 1]);
      ft = pipe_flux_update(f_top[i], dt, pipe_area, gravity, eta - (bed[i - W] + depth[i - W]), l);
    }
    if (gives_water(k, kind_at(kind, x, y + 1, W, H))) {
      const real l = pipe_length > 0 ? pipe_length : (real)0.5 * (dy[y] + dy[y + 1]);
      fb = pipe_flux_update(f_bottom[i], dt, pipe_area, gravity, eta - (bed[i + W] + depth[i + W]),
                            l);
    }
    if (k == ERODEM_CELL_ACTIVE) {
      const real K = outflow_limit(depth[i], area[y], fl + fr + ft + fb, dt);
      fl *= K;
      fr *= K;
      ft *= K;
      fb *= K;
    }
  }
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

/* ---- local inertial (Bates et al. 2010, de Almeida et al. 2012) ---------------------- */

/* New discharge per unit width q (m^2/s) across one face, positive from a to b:
 *   q <- (theta q + (1 - theta)/2 (q_up + q_down) - g h_f dt (eta_b - eta_a) / dist)
 *        / (1 + g dt n^2 |q| / h_f^(7/3)),   h_f = max(eta_a, eta_b) - max(b_a, b_b).
 * q, q_up, q_down: this face and its two neighbours in the same direction at the old time
 * (m^2/s); eta, b: water surface and bed of both cells (m); n: Manning n of the face
 * (s m^-1/3); dist between cell centres (m); dt (s); gravity (m/s^2); theta in [0, 1];
 * faces with h_f <= dry_depth (m) carry nothing. */
ERODEM_FN real local_inertial_q(real q, real q_up, real q_down, real eta_a, real eta_b, real b_a,
                                real b_b, real n, real dist, real dt, real gravity, real theta,
                                real dry_depth) {
  const real h_f = fmax(eta_a, eta_b) - fmax(b_a, b_b);
  if (!(h_f > dry_depth)) return (real)0;
  const real numerator = theta * q + ((real)1 - theta) * (real)0.5 * (q_up + q_down) -
                         gravity * h_f * dt * (eta_b - eta_a) / dist;
  const real h_f_7_3 = h_f * h_f * erodem_cbrt(h_f);
  const real denominator = (real)1 + gravity * dt * n * n * fabs(q) / h_f_7_3;
  return numerator / denominator;
}

/* Discharge (m^3/s) across the face between (x, y) and (x + 1, y), positive eastwards. */
ERODEM_FN real local_inertial_face_x(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL const real* depth,
                                     GLOBAL const real* manning, GLOBAL const real* dx,
                                     GLOBAL const real* dy, GLOBAL const real* f_left,
                                     GLOBAL const real* f_right, real dt, real gravity, real theta,
                                     real dry_depth) {
  if (!face_open(kind_at(kind, x, y, W, H), kind_at(kind, x + 1, y, W, H))) return (real)0;
  const int a = x + y * W;
  const int b = a + 1;
  const real width = dy[y];
  const real q = (f_right[a] - f_left[b]) / width;
  const real q_up =
      kind_at(kind, x - 1, y, W, H) != ERODEM_CELL_WALL ? (f_right[a - 1] - f_left[a]) / width : q;
  const real q_down =
      kind_at(kind, x + 2, y, W, H) != ERODEM_CELL_WALL ? (f_right[b] - f_left[b + 1]) / width : q;
  const real n = (real)0.5 * (manning[a] + manning[b]);
  return width * local_inertial_q(q, q_up, q_down, bed[a] + depth[a], bed[b] + depth[b], bed[a],
                                  bed[b], n, dx[y], dt, gravity, theta, dry_depth);
}

/* Discharge (m^3/s) across the face between (x, y) and (x, y + 1), positive southwards. */
ERODEM_FN real local_inertial_face_y(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL const real* depth,
                                     GLOBAL const real* manning, GLOBAL const real* dx,
                                     GLOBAL const real* dy, GLOBAL const real* f_top,
                                     GLOBAL const real* f_bottom, real dt, real gravity, real theta,
                                     real dry_depth) {
  if (!face_open(kind_at(kind, x, y, W, H), kind_at(kind, x, y + 1, W, H))) return (real)0;
  const int a = x + y * W;
  const int b = a + W;
  const real width = (real)0.5 * (dx[y] + dx[y + 1]);
  const real dist = (real)0.5 * (dy[y] + dy[y + 1]);
  const real q = (f_bottom[a] - f_top[b]) / width;
  const real q_up = kind_at(kind, x, y - 1, W, H) != ERODEM_CELL_WALL
                        ? (f_bottom[a - W] - f_top[a]) / ((real)0.5 * (dx[y - 1] + dx[y]))
                        : q;
  const real q_down = kind_at(kind, x, y + 2, W, H) != ERODEM_CELL_WALL
                          ? (f_bottom[b] - f_top[b + W]) / ((real)0.5 * (dx[y + 1] + dx[y + 2]))
                          : q;
  const real n = (real)0.5 * (manning[a] + manning[b]);
  return width * local_inertial_q(q, q_up, q_down, bed[a] + depth[a], bed[b] + depth[b], bed[a],
                                  bed[b], n, dist, dt, gravity, theta, dry_depth);
}

/* Local-inertial scheme for padded cell (x, y): the four faces around the cell, split into
 * this cell's outflows and limited like the pipes so no cell gives more than it holds. */
ERODEM_FN void flow_local_inertial_cell(
    int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
    GLOBAL const real* depth, GLOBAL const real* manning, GLOBAL const real* dx,
    GLOBAL const real* dy, GLOBAL const real* area, GLOBAL const real* f_left,
    GLOBAL const real* f_right, GLOBAL const real* f_top, GLOBAL const real* f_bottom,
    GLOBAL real* out_left, GLOBAL real* out_right, GLOBAL real* out_top, GLOBAL real* out_bottom,
    real dt, real gravity, real theta, real dry_depth) {
  const int i = x + y * W;
  const int k = kind[i];
  real fl = 0, fr = 0, ft = 0, fb = 0;
  if (k == ERODEM_CELL_ACTIVE || k == ERODEM_CELL_FIXED) {
    if (gives_water(k, kind_at(kind, x - 1, y, W, H)))
      fl = fmax((real)0, -local_inertial_face_x(x - 1, y, W, H, kind, bed, depth, manning, dx, dy,
                                                f_left, f_right, dt, gravity, theta, dry_depth));
    if (gives_water(k, kind_at(kind, x + 1, y, W, H)))
      fr = fmax((real)0, local_inertial_face_x(x, y, W, H, kind, bed, depth, manning, dx, dy,
                                               f_left, f_right, dt, gravity, theta, dry_depth));
    if (gives_water(k, kind_at(kind, x, y - 1, W, H)))
      ft = fmax((real)0, -local_inertial_face_y(x, y - 1, W, H, kind, bed, depth, manning, dx, dy,
                                                f_top, f_bottom, dt, gravity, theta, dry_depth));
    if (gives_water(k, kind_at(kind, x, y + 1, W, H)))
      fb = fmax((real)0, local_inertial_face_y(x, y, W, H, kind, bed, depth, manning, dx, dy, f_top,
                                               f_bottom, dt, gravity, theta, dry_depth));
    if (k == ERODEM_CELL_ACTIVE) {
      const real K = outflow_limit(depth[i], area[y], fl + fr + ft + fb, dt);
      fl *= K;
      fr *= K;
      ft *= K;
      fb *= K;
    }
  }
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

ERODEM_END_NAMESPACE

#endif
