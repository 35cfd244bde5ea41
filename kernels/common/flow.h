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

/* The run constants of the flow schemes (flow_params, kernels/cell_params.cpp). */
ERODEM_PARAMS_BEGIN(FlowParams)
  real gravity;      /* g (m/s^2) */
  real theta;        /* local inertial: de Almeida's weighting (1) */
  real dry_depth;    /* local inertial: faces shallower carry no flow (m) */
  real pipe_area;    /* pipes: the pipe cross-section A (m^2) */
  real pipe_length;  /* pipes: the pipe length l (m); 0 = the cell size */
  int periodic_x;    /* boundary.periodic_x: the second-order shallow water's cells two columns
                        off wrap around the seam (shallow_water_muscl_cell) */
  int manning_pitch; /* values per row of the Manning n array (param_index, compat.h) */
ERODEM_PARAMS_END(FlowParams)

ERODEM_BEGIN_NAMESPACE

/* Kind of padded cell (x, y); anything outside the padded raster is a wall. */
ERODEM_INLINE int kind_at(GLOBAL const erodem_kind_t* kind, int x, int y, int W, int H) {
  return (x < 0 || y < 0 || x >= W || y >= H) ? ERODEM_CELL_WALL : (int)kind[x + y * W];
}

/* Whether a cell of kind `from` gives water to a neighbour of kind `to` (1 or 0). Active
 * cells give to anything but walls; fixed-level ghosts give to active cells; walls and open
 * ghosts give nothing. Branch-free (bitwise), so cell loops vectorise. */
ERODEM_INLINE int gives_water(int from, int to) {
  return ((from == ERODEM_CELL_ACTIVE) & (to != ERODEM_CELL_WALL)) |
         ((from == ERODEM_CELL_FIXED) & (to == ERODEM_CELL_ACTIVE));
}

/* Whether any water crosses the face between kinds a and b (1 or 0). */
ERODEM_INLINE int face_open(int a, int b) {
  return gives_water(a, b) | gives_water(b, a);
}

/* Scale factor K of Mei et al. (2007): a cell holding `depth` (m) over `cell_area` (m^2)
 * gives at most what it holds in one step of `dt` (s) at total outflow `total_out` (m^3/s).
 * Branch-free: the division runs on a safe denominator and the result is selected. */
ERODEM_FN real outflow_limit(real depth, real cell_area, real total_out, real dt) {
  const real demand = total_out * dt;
  const real held = depth * cell_area;
  const int limited = demand > held;
  const real ratio = held / (limited ? demand : (real)1);
  return limited ? ratio : (real)1;
}

/* ---- pipes (Mei, Decaudin & Hu 2007) ------------------------------------------------ */

/* One pipe of the pipes scheme: its previous outflow f (m^3/s) plus c dh / length, with
 * c = dt A g (m^3/s), dh the surface drop towards the neighbour (m) and length the pipe's (m);
 * floored at 0 (a comparison: NaN gives 0, as fmax does, and GCC vectorises it); 0 where the
 * cell gives no water that way (`gives` 0). Computed in a block of its own, under `gives`: LLVM's
 * SLP pass packs alike instructions of one block into short vectors, and with the four pipes in
 * one block it packed two of them, after which PoCL did not vectorise the kernel across
 * work-items (the flow 6 times slower on AVX2: performance.md, "The pipes on PoCL, across
 * work-items"). The loop vectorisers (PoCL's, GCC's) turn the blocks into selects again. */
ERODEM_FN_INLINED real pipe_outflow(int gives, real f, real c, real dh, real length) {
  real out = (real)0;
  if (gives) {
    const real p = f + c * dh / length;
    out = p > 0 ? p : (real)0;
  }
  return out;
}

/* The pipes scheme (Mei, Decaudin & Hu 2007) for a cell of kind k with neighbours of kinds
 * k_left .. k_bottom: surface eta = bed + depth of the cell and eta_* of the neighbours (m),
 * its previous outflows f_* (m^3/s), pipe lengths across x and towards the cells north and
 * south (m), its depth (m) and area (m^2); dt (s), gravity g (m/s^2), pipe_area A (m^2). Active and
 * fixed-level cells give water to neighbours that take it (gives_water); a pipe that carries
 * nothing is 0; an active cell's outflows are then limited to what it holds. */
ERODEM_FN void flow_pipes_outflows(int k, int k_left, int k_right, int k_top, int k_bottom,
                                   real eta, real eta_left, real eta_right, real eta_top,
                                   real eta_bottom, real f_left, real f_right, real f_top,
                                   real f_bottom, real length_x, real length_top,
                                   real length_bottom, real depth, real cell_area, real dt,
                                   real gravity, real pipe_area, real* out_left, real* out_right,
                                   real* out_top, real* out_bottom) {
  /* Each pipe: f <- max(0, f + dt A g dh / l) (pipe_outflow). The limit is computed for every
   * cell and then selected: computed under the kind's test, the row's area was loaded in a
   * branch, which PoCL's vectoriser made a scalar load per work-item. */
  const real c = dt * pipe_area * gravity;
  const real gl = pipe_outflow(gives_water(k, k_left), f_left, c, eta - eta_left, length_x);
  const real gr = pipe_outflow(gives_water(k, k_right), f_right, c, eta - eta_right, length_x);
  const real gt = pipe_outflow(gives_water(k, k_top), f_top, c, eta - eta_top, length_top);
  const real gb =
      pipe_outflow(gives_water(k, k_bottom), f_bottom, c, eta - eta_bottom, length_bottom);
  const real limit = outflow_limit(depth, cell_area, gl + gr + gt + gb, dt);
  const real K = k == ERODEM_CELL_ACTIVE ? limit : (real)1;
  *out_left = gl * K;
  *out_right = gr * K;
  *out_top = gt * K;
  *out_bottom = gb * K;
}

/* The pipe lengths (m) of padded row y, whose neighbour rows are y_top and y_bottom:
 * pipe_length (m) where it is > 0, else the distances between cell centres, across x and to
 * the cells north and south. */
ERODEM_FN void pipe_lengths(int y, int y_top, int y_bottom, GLOBAL const real* dx,
                            GLOBAL const real* dy, real pipe_length, real* length_x,
                            real* length_top, real* length_bottom) {
  /* loaded unconditionally: a load under the condition becomes a masked gather in every
   * iteration of PoCL's vectorised work-item loop */
  const real dx_y = dx[y], dy_y = dy[y], dy_top = dy[y_top], dy_bottom = dy[y_bottom];
  const int given = pipe_length > 0;
  *length_x = given ? pipe_length : dx_y;
  *length_top = given ? pipe_length : (real)0.5 * (dy_y + dy_top);
  *length_bottom = given ? pipe_length : (real)0.5 * (dy_y + dy_bottom);
}

/* Pipes scheme for padded cell (x, y) in a row 1 <= y <= H - 2, any 0 <= x <= W - 1, with the
 * row's pipe lengths (pipe_lengths) and cell area (m^2): reads the previous fluxes f_*,
 * writes out_*. Every index it reads lies inside the raster in these rows, so it reads
 * without clamping, and the per-row values come in as numbers: loops over x vectorise. In the
 * first and last column x - 1 and x + 1 reach across the row ends to halo cells of the rows
 * above and below; the halo is not active, so no pipe between two halo cells carries water
 * (gives_water) and those reads need no mask (a mask on x kept GCC from vectorising). With
 * boundary.periodic_x the ghost columns are active, and what they compute there is overwritten
 * by the halo exchange after the flow (the copies of the columns they repeat). */
ERODEM_FN void flow_pipes_cell_interior(
    int x, int y, int W, GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
    GLOBAL const real* depth, real length_x, real length_top, real length_bottom, real cell_area,
    GLOBAL const real* f_left, GLOBAL const real* f_right, GLOBAL const real* f_top,
    GLOBAL const real* f_bottom, GLOBAL real* out_left, GLOBAL real* out_right,
    GLOBAL real* out_top, GLOBAL real* out_bottom, real dt, real gravity, real pipe_area) {
  const int i = x + y * W;
  real fl, fr, ft, fb;
  flow_pipes_outflows(kind[i], kind[i - 1], kind[i + 1], kind[i - W], kind[i + W],
                      bed[i] + depth[i], bed[i - 1] + depth[i - 1], bed[i + 1] + depth[i + 1],
                      bed[i - W] + depth[i - W], bed[i + W] + depth[i + W], f_left[i], f_right[i],
                      f_top[i], f_bottom[i], length_x, length_top, length_bottom, depth[i],
                      cell_area, dt, gravity, pipe_area, &fl, &fr, &ft, &fb);
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

/* flow_pipes_cell_interior for a cell that is active, as are its four neighbours: the same
 * outflows from the same numbers, with the kinds given as the constant ERODEM_CELL_ACTIVE instead
 * of loaded, so a compiler drops the kinds' loads and the gives_water masks (every pipe gives,
 * and the limit applies). For loops over runs of such cells (CpuBackend::flow_blocks: rows whose
 * cells and whose neighbour rows' cells are all active); it reads no kind. */
ERODEM_FN void flow_pipes_cell_all_active(int x, int y, int W, GLOBAL const real* bed,
                                          GLOBAL const real* depth, real length_x, real length_top,
                                          real length_bottom, real cell_area,
                                          GLOBAL const real* f_left, GLOBAL const real* f_right,
                                          GLOBAL const real* f_top, GLOBAL const real* f_bottom,
                                          GLOBAL real* out_left, GLOBAL real* out_right,
                                          GLOBAL real* out_top, GLOBAL real* out_bottom, real dt,
                                          real gravity, real pipe_area) {
  const int i = x + y * W;
  const int a = ERODEM_CELL_ACTIVE;
  real fl, fr, ft, fb;
  flow_pipes_outflows(a, a, a, a, a, bed[i] + depth[i], bed[i - 1] + depth[i - 1],
                      bed[i + 1] + depth[i + 1], bed[i - W] + depth[i - W],
                      bed[i + W] + depth[i + W], f_left[i], f_right[i], f_top[i], f_bottom[i],
                      length_x, length_top, length_bottom, depth[i], cell_area, dt, gravity,
                      pipe_area, &fl, &fr, &ft, &fb);
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

/* Pipes scheme for any padded cell (rows 0 and H - 1 clamp their indices; beyond the raster
 * are walls); pipe_length (m) as for pipe_lengths. */
ERODEM_FN void flow_pipes_cell(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                               GLOBAL const real* bed, GLOBAL const real* depth,
                               GLOBAL const real* dx, GLOBAL const real* dy,
                               GLOBAL const real* area, GLOBAL const real* f_left,
                               GLOBAL const real* f_right, GLOBAL const real* f_top,
                               GLOBAL const real* f_bottom, GLOBAL real* out_left,
                               GLOBAL real* out_right, GLOBAL real* out_top,
                               GLOBAL real* out_bottom, real dt, real gravity, real pipe_area,
                               real pipe_length) {
  const int yt = y >= 1 ? y - 1 : y, yb = y <= H - 2 ? y + 1 : y; /* clamped: masked */
  real lx, lt, lb;
  pipe_lengths(y, yt, yb, dx, dy, pipe_length, &lx, &lt, &lb);
  if (y >= 1 && y <= H - 2) {
    flow_pipes_cell_interior(x, y, W, kind, bed, depth, lx, lt, lb, area[y], f_left, f_right, f_top,
                             f_bottom, out_left, out_right, out_top, out_bottom, dt, gravity,
                             pipe_area);
    return;
  }
  const int i = x + y * W;
  const int xl = x >= 1 ? x - 1 : x, xr = x <= W - 2 ? x + 1 : x;
  const int il = xl + y * W, ir = xr + y * W, it = x + yt * W, ib = x + yb * W;
  real fl, fr, ft, fb;
  flow_pipes_outflows(kind[i], kind_at(kind, x - 1, y, W, H), kind_at(kind, x + 1, y, W, H),
                      kind_at(kind, x, y - 1, W, H), kind_at(kind, x, y + 1, W, H),
                      bed[i] + depth[i], bed[il] + depth[il], bed[ir] + depth[ir],
                      bed[it] + depth[it], bed[ib] + depth[ib], f_left[i], f_right[i], f_top[i],
                      f_bottom[i], lx, lt, lb, depth[i], area[y], dt, gravity, pipe_area, &fl, &fr,
                      &ft, &fb);
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

/* ---- local inertial (Bates et al. 2010, de Almeida et al. 2012) ---------------------- */
/* The discharge is a face quantity: each face is computed once (local_inertial_face), from
 * the outflows of the previous step, and then split into the outflows of the cells beside it
 * and limited (local_inertial_split). The CPU loop (kernels/cpu/flow.cpp) computes a row of
 * faces at a time; the OpenCL kernels (kernels/opencl/flow.cl) a face pass and a cell pass.
 * Both evaluate the same expressions on the same numbers, so they agree bit for bit. */

/* Flow depth (m) at or below which a face is dry whatever numerics.dry_depth says: from
 * here up h_f^(7/3) is a normal float (1e-16^(7/3) = 4.6e-38), so the friction term
 * |q| / h_f^(7/3) is never 0 / 0, and h_f lies in the range of erodem_cbrt_positive. A
 * film this thin (a millionth of an atom) carries nothing that a float can tell apart
 * from 0. */
#define ERODEM_FACE_DEPTH_MIN 1.0e-16f

/* Flow depth (m) at the face between cells a and b of depths d and beds b (m): the water
 * above the higher bed, max(b_a + d_a, b_b + d_b) - max(b_a, b_b), written with the bed step
 * db = b_b - b_a as max(d_a, d_b + db) - max(db, 0). The two are equal in exact arithmetic,
 * but the first subtracts elevations: in float32 at 9000 m it rounds to ulp(9000 m) = 1e-3 m,
 * the depth of a whole film. The step between neighbours is exact by Sterbenz wherever their
 * beds are within a factor of two, so this form rounds only at the size of d and db. The
 * local-inertial discharge and every cell velocity (water.h) use it. */
ERODEM_FN real face_flow_depth(real d_a, real d_b, real b_a, real b_b) {
  const real db = b_b - b_a;
  return erodem_max(d_a, d_b + db) - erodem_max(db, (real)0);
}

/* Discharge per unit width (m^2/s) across a face at the old time, from the outflow of the
 * cell before it towards the cell after it, out_ab, the outflow back, out_ba (m^3/s), and
 * the face width (m). */
ERODEM_FN real face_unit_discharge(real out_ab, real out_ba, real width) {
  return (out_ab - out_ba) / width;
}

/* New discharge per unit width q' (m^2/s) across one face, positive from a to b, with the
 * friction implicit in the new discharge:
 *   q' (1 + F |q'|) = N,   N = theta q + (1 - theta)/2 (q_up + q_down)
 *                              - g h_f dt (eta_b - eta_a) / dist,
 *   F = g dt n^2 / h_f^(7/3),   h_f = max(eta_a, eta_b) - max(b_a, b_b) (face_flow_depth),
 * solved exactly: q' = 2 N / (1 + sqrt(1 + 4 F |N|)) (the root of the quadratic without
 * cancellation). de Almeida et al. (2012) take |q| of the old time in F instead; where
 * F |N| >> 1 (a thin film on a steep cell: 1 mm on a slope of 0.5 with dt = 5 s gives
 * 4 F |N| ~ 4e4) that iteration q -> (q + G) / (1 + F q) has slope -> -1 at its fixed
 * point, so the discharge swings about the Manning value from step to step and its
 * peaks, limited only by what the cell holds, reached dx/dt (59.9 m/s on Big Tujunga).
 * The implicit root is the Manning discharge h_f^(5/3) S^(1/2) / n there whatever dt is,
 * and the same fixed point as before wherever flow is steady (docs/model.md section 5,
 * "Friction"). n = 0 gives q' = N exactly (2N / 2), so frictionless runs are unchanged.
 * q, q_up, q_down: this face and its two neighbours in the same direction at the old time
 * (m^2/s); d, b: depth and bed of both cells (m), eta = b + d; n: Manning n of the face
 * (s m^-1/3); dist between cell centres (m); dt (s); gravity (m/s^2); theta in [0, 1];
 * faces with h_f <= dry_depth (m), or h_f <= ERODEM_FACE_DEPTH_MIN whatever dry_depth is,
 * carry nothing. Branch-free: a dry face is evaluated on h_f = 1 and its result replaced
 * by 0. */
ERODEM_FN real local_inertial_q(real q, real q_up, real q_down, real d_a, real d_b, real b_a,
                                real b_b, real n, real dist, real dt, real gravity, real theta,
                                real dry_depth) {
  const real eta_a = b_a + d_a, eta_b = b_b + d_b;
  const real h_raw = face_flow_depth(d_a, d_b, b_a, b_b);
  /* one threshold, the same for every face (hoisted out of the cell loops) */
  const real wet_above =
      dry_depth > (real)ERODEM_FACE_DEPTH_MIN ? dry_depth : (real)ERODEM_FACE_DEPTH_MIN;
  const int wet = h_raw > wet_above;
  const real h_f = wet ? h_raw : (real)1;
  const real numerator = theta * q + ((real)1 - theta) * (real)0.5 * (q_up + q_down) -
                         gravity * h_f * dt * (eta_b - eta_a) / dist;
  const real h_f_7_3 = h_f * h_f * erodem_cbrt_positive(h_f); /* normal, > 0 */
  /* 4 F |N|: |N| in the numerator, so N = 0 gives 0 (never 0 * inf); an overflow to inf
   * gives q' = 0 */
  const real four_f_n = (real)4 * gravity * dt * n * n * fabs(numerator) / h_f_7_3;
  const real q_new = (real)2 * numerator / ((real)1 + sqrt((real)1 + four_f_n));
  return wet ? q_new : (real)0;
}

/* Discharge (m^3/s) across one face, positive from cell a to cell b, from the unit
 * discharges of the previous step: q of this face, q_up of the face before a and q_down of
 * the face after b (m^2/s), each used when the cell beyond is no wall (up_open, down_open;
 * else q stands in). open: whether water crosses the face at all (face_open). Depths d
 * and beds b (m), Manning n of both cells (s m^-1/3), face width and
 * distance between the cell centres (m), dt (s), gravity (m/s^2), theta (1), dry_depth (m). */
ERODEM_FN real local_inertial_face(int open, int up_open, int down_open, real q, real q_up,
                                   real q_down, real d_a, real d_b, real b_a, real b_b, real n_a,
                                   real n_b, real width, real dist, real dt, real gravity,
                                   real theta, real dry_depth) {
  const real n = (real)0.5 * (n_a + n_b);
  const real discharge =
      width * local_inertial_q(q, up_open ? q_up : q, down_open ? q_down : q, d_a, d_b, b_a, b_b, n,
                               dist, dt, gravity, theta, dry_depth);
  return open ? discharge : (real)0;
}

/* Discharge (m^3/s) across the face from padded cell a to padded cell b (the OpenCL face
 * pass): out_ab, out_ba are the outflow fields towards b and back (f_right, f_left or
 * f_bottom, f_top); `up` is the cell before a and `down` the cell after b in the same
 * direction (any index inside the raster where up_open / down_open is 0); width_up, width,
 * width_down the widths of the faces up-a, a-b, b-down and dist the distance a-b (m); n_a, n_b
 * Manning's n of a and b (s/m^(1/3)). */
ERODEM_FN real local_inertial_face_at(int a, int b, int up, int down, int up_open, int down_open,
                                      real width_up, real width, real width_down, real dist,
                                      GLOBAL const erodem_kind_t* kind, GLOBAL const real* bed,
                                      GLOBAL const real* depth, real n_a, real n_b,
                                      GLOBAL const real* out_ab, GLOBAL const real* out_ba, real dt,
                                      real gravity, real theta, real dry_depth) {
  return local_inertial_face(face_open(kind[a], kind[b]), up_open, down_open,
                             face_unit_discharge(out_ab[a], out_ba[b], width),
                             face_unit_discharge(out_ab[up], out_ba[a], width_up),
                             face_unit_discharge(out_ab[b], out_ba[down], width_down), depth[a],
                             depth[b], bed[a], bed[b], n_a, n_b, width, dist, dt, gravity, theta,
                             dry_depth);
}

/* Discharge (m^3/s) across the face between padded cells (x, y) and (x + 1, y), positive
 * eastwards, in a row 1 <= y <= H - 2, for 0 <= x <= W - 2 (any value for x = W - 1: no such
 * face). Every index it reads lies inside the raster in these rows, so it reads without
 * clamping (consecutive loads across x, which OpenCL CPU compilers vectorise), masking the
 * edge columns by x. Manning n at param_index(x + 1, y, manning_pitch): for x = W - 1 and a
 * uniform Manning n (pitch 0) that is index W, so a one-row array holds W + 1 values
 * (OpenClBackend::take_parameter). */
ERODEM_FN real local_inertial_face_x_interior(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                              GLOBAL const real* bed, GLOBAL const real* depth,
                                              GLOBAL const real* manning, int manning_pitch,
                                              GLOBAL const real* dx, GLOBAL const real* dy,
                                              GLOBAL const real* f_left, GLOBAL const real* f_right,
                                              real dt, real gravity, real theta, real dry_depth) {
  const real width = dy[y];
  const int a = x + y * W; /* a - 1 >= 0 and a + 2 < W * H */
  return local_inertial_face_at(
      a, a + 1, a - 1, a + 2, (x >= 1) & (kind[a - 1] != ERODEM_CELL_WALL),
      (x + 2 <= W - 1) & (kind[a + 2] != ERODEM_CELL_WALL), width, width, width, dx[y], kind, bed,
      depth, manning[param_index(x, y, manning_pitch)],
      manning[param_index(x + 1, y, manning_pitch)], f_right, f_left, dt, gravity, theta,
      dry_depth);
}

/* The same for any row 0 <= y <= H - 1: rows 0 and H - 1 clamp their indices. */
ERODEM_FN real local_inertial_face_x(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL const real* depth,
                                     GLOBAL const real* manning, int manning_pitch,
                                     GLOBAL const real* dx, GLOBAL const real* dy,
                                     GLOBAL const real* f_left, GLOBAL const real* f_right, real dt,
                                     real gravity, real theta, real dry_depth) {
  if (y >= 1 && y <= H - 2)
    return local_inertial_face_x_interior(x, y, W, kind, bed, depth, manning, manning_pitch, dx, dy,
                                          f_left, f_right, dt, gravity, theta, dry_depth);
  const real width = dy[y];
  const int xc = x <= W - 2 ? x : W - 2;
  const int a = xc + y * W;
  return local_inertial_face_at(a, a + 1, xc >= 1 ? a - 1 : a, xc + 2 <= W - 1 ? a + 2 : a + 1,
                                kind_at(kind, xc - 1, y, W, H) != ERODEM_CELL_WALL,
                                kind_at(kind, xc + 2, y, W, H) != ERODEM_CELL_WALL, width, width,
                                width, dx[y], kind, bed, depth,
                                manning[param_index(xc, y, manning_pitch)],
                                manning[param_index(xc + 1, y, manning_pitch)], f_right, f_left, dt,
                                gravity, theta, dry_depth);
}

/* boundary.periodic_x (the OpenCL seam pass; the CPU's face_x_row evaluates the same): the
 * discharge (m^3/s) across the seam in padded row y, the face east of the last DEM column
 * (W - 2), whose east ghost repeats column 1, with its true neighbours, the face before it and
 * the face between columns 1 and 2 after it. The host writes it to both faces that stand for
 * it, east of column W - 2 and east of ghost column 0. */
ERODEM_FN real local_inertial_seam_x(int y, int W, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL const real* depth,
                                     GLOBAL const real* manning, int manning_pitch,
                                     GLOBAL const real* dx, GLOBAL const real* dy,
                                     GLOBAL const real* f_left, GLOBAL const real* f_right, real dt,
                                     real gravity, real theta, real dry_depth) {
  const int a = W - 2 + y * W, down = 2 + y * W;
  const real width = dy[y];
  return local_inertial_face_at(a, a + 1, a - 1, down, kind[a - 1] != ERODEM_CELL_WALL,
                                kind[down] != ERODEM_CELL_WALL, width, width, width, dx[y], kind,
                                bed, depth, manning[param_index(W - 2, y, manning_pitch)],
                                manning[param_index(W - 1, y, manning_pitch)], f_right, f_left, dt,
                                gravity, theta, dry_depth);
}

/* Discharge (m^3/s) across the face between padded cells (x, y) and (x, y + 1), positive
 * southwards, in a row 1 <= y <= H - 3 (every index inside the raster: no clamping). */
ERODEM_FN real local_inertial_face_y_interior(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                              GLOBAL const real* bed, GLOBAL const real* depth,
                                              GLOBAL const real* manning, int manning_pitch,
                                              GLOBAL const real* dx, GLOBAL const real* dy,
                                              GLOBAL const real* f_top, GLOBAL const real* f_bottom,
                                              real dt, real gravity, real theta, real dry_depth) {
  const int a = x + y * W; /* a - W >= 0 and a + 2 W < W * H */
  return local_inertial_face_at(
      a, a + W, a - W, a + 2 * W, kind[a - W] != ERODEM_CELL_WALL,
      kind[a + 2 * W] != ERODEM_CELL_WALL, face_y_width(dx, y - 1), face_y_width(dx, y),
      face_y_width(dx, y + 1), centre_distance_y(dy, y), kind, bed, depth,
      manning[param_index(x, y, manning_pitch)], manning[param_index(x, y + 1, manning_pitch)],
      f_bottom, f_top, dt, gravity, theta, dry_depth);
}

/* The same for any row 0 <= y <= H - 1 (any value for y = H - 1: no such face); rows 0,
 * H - 2 and H - 1 clamp their indices. */
ERODEM_FN real local_inertial_face_y(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                     GLOBAL const real* bed, GLOBAL const real* depth,
                                     GLOBAL const real* manning, int manning_pitch,
                                     GLOBAL const real* dx, GLOBAL const real* dy,
                                     GLOBAL const real* f_top, GLOBAL const real* f_bottom, real dt,
                                     real gravity, real theta, real dry_depth) {
  if (y >= 1 && y <= H - 3)
    return local_inertial_face_y_interior(x, y, W, kind, bed, depth, manning, manning_pitch, dx, dy,
                                          f_top, f_bottom, dt, gravity, theta, dry_depth);
  const int yc = y <= H - 2 ? y : H - 2;
  const int a = x + yc * W;
  const int y_up = yc >= 1 ? yc - 1 : yc;           /* clamped: unused at the edge */
  const int y_down = yc + 2 <= H - 1 ? yc + 1 : yc; /* clamped: unused at the edge */
  return local_inertial_face_at(
      a, a + W, x + y_up * W, x + (y_down + 1) * W,
      kind_at(kind, x, yc - 1, W, H) != ERODEM_CELL_WALL,
      kind_at(kind, x, yc + 2, W, H) != ERODEM_CELL_WALL, face_y_width(dx, y_up),
      face_y_width(dx, yc), face_y_width(dx, y_down), centre_distance_y(dy, yc), kind, bed, depth,
      manning[param_index(x, yc, manning_pitch)], manning[param_index(x, yc + 1, manning_pitch)],
      f_bottom, f_top, dt, gravity, theta, dry_depth);
}

/* The four face discharges around a cell of kind k (m^3/s; q_left, q_top positive into the
 * cell, q_right, q_bottom positive out of it) split into the cell's outflows, limited like
 * the pipes so that an active cell gives no more than its depth (m) over cell_area (m^2)
 * holds in dt (s). k_*: the neighbours' kinds. Writes the outflows (m^3/s, >= 0). */
ERODEM_FN void local_inertial_split(int k, int k_left, int k_right, int k_top, int k_bottom,
                                    real q_left, real q_right, real q_top, real q_bottom,
                                    real depth, real cell_area, real dt, real* out_left,
                                    real* out_right, real* out_top, real* out_bottom) {
  const real fl = gives_water(k, k_left) & (-q_left > 0) ? -q_left : (real)0;
  const real fr = gives_water(k, k_right) & (q_right > 0) ? q_right : (real)0;
  const real ft = gives_water(k, k_top) & (-q_top > 0) ? -q_top : (real)0;
  const real fb = gives_water(k, k_bottom) & (q_bottom > 0) ? q_bottom : (real)0;
  /* the limit for every cell, then selected: under the condition, its division (and the
   * row's area with it) went into a branch that PoCL turned into a gather per iteration
   * (15.1 -> 14.4 ms at 4096^2), as in flow_pipes_outflows. */
  const real limit = outflow_limit(depth, cell_area, fl + fr + ft + fb, dt);
  const real K = k == ERODEM_CELL_ACTIVE ? limit : (real)1;
  *out_left = fl * K;
  *out_right = fr * K;
  *out_top = ft * K;
  *out_bottom = fb * K;
}

/* Cell pass of the local-inertial scheme for padded cell (x, y) in a row 1 <= y <= H - 2
 * (the OpenCL cell kernel): reads the face discharges face_x (the face east of each cell, 0
 * in the last column) and face_y (south of each cell) of the face pass without clamping,
 * masking the edge columns by x; writes the cell's four outflows. */
ERODEM_FN void flow_local_inertial_cell_interior(int x, int y, int W,
                                                 GLOBAL const erodem_kind_t* kind,
                                                 GLOBAL const real* depth, GLOBAL const real* area,
                                                 GLOBAL const real* face_x,
                                                 GLOBAL const real* face_y, GLOBAL real* out_left,
                                                 GLOBAL real* out_right, GLOBAL real* out_top,
                                                 GLOBAL real* out_bottom, real dt) {
  const int i = x + y * W;
  const real q_left = face_x[i - 1];
  const int k_left = kind[i - 1], k_right = kind[i + 1];
  real fl, fr, ft, fb;
  local_inertial_split(kind[i], x >= 1 ? k_left : ERODEM_CELL_WALL,
                       x <= W - 2 ? k_right : ERODEM_CELL_WALL, (int)kind[i - W], (int)kind[i + W],
                       x >= 1 ? q_left : (real)0, face_x[i], face_y[i - W], face_y[i], depth[i],
                       area[y], dt, &fl, &fr, &ft, &fb);
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

/* The same for any padded cell (rows 0 and H - 1 clamp their indices). */
ERODEM_FN void flow_local_inertial_cell(int x, int y, int W, int H,
                                        GLOBAL const erodem_kind_t* kind, GLOBAL const real* depth,
                                        GLOBAL const real* area, GLOBAL const real* face_x,
                                        GLOBAL const real* face_y, GLOBAL real* out_left,
                                        GLOBAL real* out_right, GLOBAL real* out_top,
                                        GLOBAL real* out_bottom, real dt) {
  if (y >= 1 && y <= H - 2) {
    flow_local_inertial_cell_interior(x, y, W, kind, depth, area, face_x, face_y, out_left,
                                      out_right, out_top, out_bottom, dt);
    return;
  }
  const int i = x + y * W;
  const real q_left = x > 0 ? face_x[x > 0 ? i - 1 : i] : (real)0;
  const real q_top = y > 0 ? face_y[y > 0 ? i - W : i] : (real)0;
  const real q_bottom = y < H - 1 ? face_y[i] : (real)0;
  real fl, fr, ft, fb;
  local_inertial_split(kind[i], kind_at(kind, x - 1, y, W, H), kind_at(kind, x + 1, y, W, H),
                       kind_at(kind, x, y - 1, W, H), kind_at(kind, x, y + 1, W, H), q_left,
                       face_x[i], q_top, q_bottom, depth[i], area[y], dt, &fl, &fr, &ft, &fb);
  out_left[i] = fl;
  out_right[i] = fr;
  out_top[i] = ft;
  out_bottom[i] = fb;
}

ERODEM_END_NAMESPACE

#endif
