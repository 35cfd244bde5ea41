/* erodem — water update and velocity (MODEL.md step 3). */
#ifndef ERODEM_KERNELS_COMMON_WATER_H
#define ERODEM_KERNELS_COMMON_WATER_H

#include "flow.h"

/* The run constants of the water update (water_params, kernels/cell_params.cpp). */
ERODEM_PARAMS_BEGIN(WaterParams)
  real velocity_min_depth; /* the velocity is 0 below this mean depth (m) */
ERODEM_PARAMS_END(WaterParams)

ERODEM_BEGIN_NAMESPACE

/* Depth-averaged velocity (m/s) of a cell along one axis: the mean of the velocities through
 * its two opposite faces, each the face's discharge through_a, through_b (m^3/s, positive in
 * the velocity's direction) over its flow area, width (m) times its flow depth depth_a,
 * depth_b (m; face_flow_depth of the depths the update starts from). 0 where the cell's mean depth
 * of the step, mean_depth (m), is below min_depth (m); a face depth below min_depth counts as
 * min_depth. The flow depth, not the cell's mean depth: a thin cell that a deep neighbour
 * pours into carries the neighbour's discharge at the neighbour's depth (a 0.5 m pool spilling
 * into a 1 mm cell read 73 m/s from discharge over mean depth, and the adaptive step, which
 * takes the largest speed, shrank to milliseconds). Branch-free, so loops over cells
 * vectorise. */
ERODEM_FN real face_velocity(real through_a, real depth_a, real through_b, real depth_b, real width,
                             real mean_depth, real min_depth) {
  const int flowing = (mean_depth >= min_depth) & (mean_depth > 0);
  const real floor =
      min_depth > (real)ERODEM_FACE_DEPTH_MIN ? min_depth : (real)ERODEM_FACE_DEPTH_MIN;
  const real h_a = depth_a > floor ? depth_a : floor;
  const real h_b = depth_b > floor ? depth_b : floor;
  const real v = (through_a / h_a + through_b / h_b) * (real)0.5 / width;
  return flowing ? v : (real)0;
}

/* Net discharge (m^3/s) out of the domain through the faces that padded cell i shares with
 * ghosts (walls carry nothing): what flows out minus what flows in. Only cells beside a ghost
 * have one (the OpenCL backend sums it over a list of them, kernels/opencl/edges.cl). */
ERODEM_FN real water_exchange_cell(int i, int W, GLOBAL const erodem_kind_t* kind,
                                   GLOBAL const real* f_left, GLOBAL const real* f_right,
                                   GLOBAL const real* f_top, GLOBAL const real* f_bottom) {
  return (kind[i - 1] != ERODEM_CELL_ACTIVE ? f_left[i] - f_right[i - 1] : (real)0) +
         (kind[i + 1] != ERODEM_CELL_ACTIVE ? f_right[i] - f_left[i + 1] : (real)0) +
         (kind[i - W] != ERODEM_CELL_ACTIVE ? f_top[i] - f_bottom[i - W] : (real)0) +
         (kind[i + W] != ERODEM_CELL_ACTIVE ? f_bottom[i] - f_top[i + W] : (real)0);
}

/* Whether padded cell i is active and shares a face with a cell that is not (a ghost, a wall
 * or a nodata cell): the only cells for which water_exchange_cell and the sediment's
 * transport_boundary_out_cell can be non-zero. The kinds never change, so each backend lists
 * these cells once and sums those tallies over the list (CpuBackend's edge_x_, OpenCL's
 * edge_cells_ for edges.cl). */
ERODEM_INLINE int active_beside_inactive(int i, int W, GLOBAL const erodem_kind_t* kind) {
  return kind[i] == ERODEM_CELL_ACTIVE &&
         (kind[i - 1] != ERODEM_CELL_ACTIVE || kind[i + 1] != ERODEM_CELL_ACTIVE ||
          kind[i - W] != ERODEM_CELL_ACTIVE || kind[i + W] != ERODEM_CELL_ACTIVE);
}

/* The depth (m) of a cell of depth d (m) and area (m^2) after dt (s) of inflow and outflow
 * (m^3/s). */
ERODEM_FN real depth_after_fluxes(real d, real inflow, real outflow, real dt, real area) {
  return d + dt * (inflow - outflow) / area;
}

/* Water update of padded cell (x, y) (active cells change; others keep their depth):
 *   d <- d + dt (sum inflow - sum outflow) / area,
 * velocity_x (eastwards) and velocity_y (northwards) from the fluxes and the faces' flow depths
 * (face_velocity; bed (m) gives those). Writes depth_out; returns
 * through *exchange the net discharge out of the domain through this cell's faces with ghosts
 * (m^3/s), through *clipped the volume (m^3) added to lift a rounding-level negative depth back to
 * zero, and through *given the volume (m^3) the cell gave through its faces (0 for other cells).
 * Branch-free. */
ERODEM_FN void water_update_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                 GLOBAL const real* bed, GLOBAL const real* depth,
                                 GLOBAL real* depth_out, GLOBAL const real* f_left,
                                 GLOBAL const real* f_right, GLOBAL const real* f_top,
                                 GLOBAL const real* f_bottom, GLOBAL const real* dx,
                                 GLOBAL const real* dy, GLOBAL const real* area,
                                 GLOBAL real* velocity_x, GLOBAL real* velocity_y, real dt,
                                 ERODEM_P(WaterParams) p, real* exchange, real* clipped,
                                 real* given) {
  const int i = x + y * W;
  const int active = kind[i] == ERODEM_CELL_ACTIVE;
  /* what each neighbour gives to this cell */
  const real in_left = f_right[i - 1];
  const real in_right = f_left[i + 1];
  const real in_top = f_bottom[i - W];
  const real in_bottom = f_top[i + W];
  const real inflow = in_left + in_right + in_top + in_bottom;
  const real outflow = f_left[i] + f_right[i] + f_top[i] + f_bottom[i];
  const real d_old = depth[i];
  const real d_raw = depth_after_fluxes(d_old, inflow, outflow, dt, area[y]);
  /* The outflow limit keeps d_raw >= 0 up to rounding: lift such a rounding-level negative
   * to 0 and book the volume; anything deeper is left for the stability check to stop. */
  const real rounding = (real)64 * ERODEM_EPSILON(real) * (d_old + dt * inflow / area[y]);
  /* -d_raw <= rounding, not d_raw >= -rounding (the same truth for every value): through the
   * latter LLVM's SLP pass paired d_raw with the sum inside the rounding bound, both
   * d_old + dt x / area, in one vector of two, and PoCL then left water_update and water_erosion
   * scalar across work-items on AVX2 (about 4.5x slower; tests/pocl_vectorisation.sh,
   * performance.md "PoCL's water update and thermal share vectorised on AVX2"). */
  const int lift = (d_raw < 0) & (-d_raw <= rounding);
  const real d_new = lift ? (real)0 : d_raw;
  const real clip = active & lift ? -d_raw * area[y] : (real)0;
  *clipped = clip;
  *given = active ? dt * outflow : (real)0;
  depth_out[i] = active ? d_new : d_old;

  /* net outflow through faces shared with ghosts; computed on every cell and selected (the
   * neighbours' kinds loaded unconditionally: under `active`, GCC 12 could not if-convert
   * those loads and left the CPU loop scalar). Both backends leave it unused and sum it over
   * the cells beside a ghost only (edges.cl; CpuBackend::water_row), so their compilers drop
   * it from the cell loop. */
  const real ghost_exchange = water_exchange_cell(i, W, kind, f_left, f_right, f_top, f_bottom);
  *exchange = active ? ghost_exchange : (real)0;

  const real d_mean = (real)0.5 * (d_old + d_new);
  /* the flow depths of the four faces, from the depths this update starts from: those the flow
   * step saw plus this step's sources, which run between the two (model.md section 2) */
  const real b = bed[i];
  const real b_l = bed[i - 1], b_r = bed[i + 1], b_t = bed[i - W], b_b = bed[i + W];
  /* face_flow_depth, written out in other operand orders for the east and south faces (the
   * same values: max and + commute, and face_velocity floors the depth at a positive value,
   * so a zero's sign cannot reach the velocity). Written alike, LLVM's SLP vectoriser packed
   * the four into a vector and PoCL then left water_update scalar across work-items on AVX-512
   * (tests/pocl_vectorisation.sh: 36 instead of 39 loops 8 wide). */
  const real h_l = face_flow_depth(depth[i - 1], d_old, b_l, b);
  const real db_r = b_r - b, db_b = b_b - b;
  const real h_r = erodem_max(depth[i + 1] + db_r, d_old) - erodem_max((real)0, db_r);
  const real h_t = face_flow_depth(depth[i - W], d_old, b_t, b);
  const real h_b = erodem_max(db_b + depth[i + W], d_old) - (db_b > 0 ? db_b : (real)0);
  const real u = face_velocity(in_left - f_left[i], h_l, f_right[i] - in_right, h_r, dy[y], d_mean,
                               p.velocity_min_depth);
  const real v = face_velocity(in_bottom - f_bottom[i], h_b, f_top[i] - in_top, h_t, dx[y], d_mean,
                               p.velocity_min_depth);
  velocity_x[i] = active ? u : (real)0;
  velocity_y[i] = active ? v : (real)0;
}

ERODEM_END_NAMESPACE

#endif
