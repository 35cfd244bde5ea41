/* erodem OpenCL — flow process: kernels/common/flow.h over every padded cell (ghosts give
 * water too), as the CPU loop of kernels/cpu/flow.cpp. Local inertial's cell pass writes the
 * outflows in place (it reads only the faces), as do the pipes (each cell reads only its own);
 * shallow water writes second buffers, which the host then swaps. Manning n is read at param_index
 * with p.manning_pitch (one row where uniform). */
#pragma OPENCL FP_CONTRACT OFF
#include "flow.h"
#include "shallow_water.h"

/* One work-item per padded cell (where the global size is rounded up, the work-items past
 * the raster stop); the host runs flow_pipes_interior on rows 1 .. H - 2 and this one on rows
 * 0 and H - 1. A cell reads only its own previous outflows f_* and writes its new ones out_*:
 * the host binds the same buffers to both (the outflows in place, as on the CPU), so neither
 * is restrict. */
__kernel void flow_pipes(int W, int H, __global const uchar* restrict kind,
                         __global const real* restrict bed, __global const real* restrict depth,
                         __global const real* restrict dx, __global const real* restrict dy,
                         __global const real* restrict area, __global const real* f_left,
                         __global const real* f_right, __global const real* f_top,
                         __global const real* f_bottom, __global real* out_left,
                         __global real* out_right, __global real* out_top,
                         __global real* out_bottom, real dt, FlowParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  flow_pipes_cell(x, y, W, H, kind, bed, depth, dx, dy, area, f_left, f_right, f_top, f_bottom,
                  out_left, out_right, out_top, out_bottom, dt, p.gravity, p.pipe_area,
                  p.pipe_length);
}

/* The pipes scheme on rows 1 .. H - 2 (global offset 1): no clamping, no branches. */
__kernel void flow_pipes_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict dx,
    __global const real* restrict dy, __global const real* restrict area,
    __global const real* f_left, __global const real* f_right, __global const real* f_top,
    __global const real* f_bottom, __global real* out_left, __global real* out_right,
    __global real* out_top, __global real* out_bottom, real dt, FlowParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  real lx, lt, lb;
  pipe_lengths(y, y - 1, y + 1, dx, dy, p.pipe_length, &lx, &lt, &lb);
  flow_pipes_cell_interior(x, y, W, kind, bed, depth, lx, lt, lb, area[y], f_left, f_right, f_top,
                           f_bottom, out_left, out_right, out_top, out_bottom, dt, p.gravity,
                           p.pipe_area);
}

/* Local inertial, face pass: one work-item per padded cell computes the face east of it
 * (face_x, x <= W - 2) and the face south of it (face_y, y <= H - 2), each face once; the
 * last column and row have no face east / south: computed on what is there, stored as 0.
 * The host runs flow_local_inertial_faces_x_interior and _y_interior on rows 1 .. H - 3
 * (global offset 1) and this one on the other rows. */
__kernel void flow_local_inertial_faces(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global real* restrict face_x, __global real* restrict face_y, real dt, FlowParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  const int i = x + y * W;
  const real qx = local_inertial_face_x(x, y, W, H, kind, bed, depth, manning, p.manning_pitch, dx,
                                        dy, f_left, f_right, dt, p.gravity, p.theta, p.dry_depth);
  const real qy = local_inertial_face_y(x, y, W, H, kind, bed, depth, manning, p.manning_pitch, dx,
                                        dy, f_top, f_bottom, dt, p.gravity, p.theta, p.dry_depth);
  face_x[i] = x < W - 1 ? qx : (real)0;
  face_y[i] = y < H - 1 ? qy : (real)0;
}

/* The face pass on rows 1 .. H - 3, in two kernels, the faces east of the cells and the faces
 * south of them: no clamping, no branches but the column mask. (One kernel for both faces
 * ran 53 ms at 4096^2 on PoCL, these two 19 + 25 ms: each face's chain of divisions and cube
 * root is long, and the loop with one chain keeps more iterations in flight.) Both take the
 * parameters of flow_local_inertial_faces. */
__kernel void flow_local_inertial_faces_x_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global real* restrict face_x, __global real* restrict face_y, real dt, FlowParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  const real qx =
      local_inertial_face_x_interior(x, y, W, kind, bed, depth, manning, p.manning_pitch, dx, dy,
                                     f_left, f_right, dt, p.gravity, p.theta, p.dry_depth);
  face_x[x + y * W] = x < W - 1 ? qx : (real)0;
}

__kernel void flow_local_inertial_faces_y_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global real* restrict face_x, __global real* restrict face_y, real dt, FlowParams p) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  face_y[x + y * W] =
      local_inertial_face_y_interior(x, y, W, kind, bed, depth, manning, p.manning_pitch, dx, dy,
                                     f_top, f_bottom, dt, p.gravity, p.theta, p.dry_depth);
}

/* boundary.periodic_x: the faces across the seam after the face pass, one work-item per padded
 * row (local_inertial_seam_x), into face_x east of column W - 2 and of ghost column 0. */
__kernel void flow_local_inertial_seam_x(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global real* restrict face_x, real dt, FlowParams p) {
  const int y = (int)get_global_id(0);
  if (y >= H) return;
  const real q = local_inertial_seam_x(y, W, kind, bed, depth, manning, p.manning_pitch, dx, dy,
                                       f_left, f_right, dt, p.gravity, p.theta, p.dry_depth);
  face_x[W - 2 + y * W] = q;
  face_x[y * W] = q;
}

/* Local inertial, cell pass: the four faces around each padded cell split into its
 * outflows (flow_local_inertial_cell); the host runs flow_local_inertial_split_interior on
 * rows 1 .. H - 2 and this one on rows 0 and H - 1. */
__kernel void flow_local_inertial_split(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict depth,
    __global const real* restrict area, __global const real* restrict face_x,
    __global const real* restrict face_y, __global real* restrict out_left,
    __global real* restrict out_right, __global real* restrict out_top,
    __global real* restrict out_bottom, real dt) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  flow_local_inertial_cell(x, y, W, H, kind, depth, area, face_x, face_y, out_left, out_right,
                           out_top, out_bottom, dt);
}

/* The cell pass on rows 1 .. H - 2. */
__kernel void flow_local_inertial_split_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict depth,
    __global const real* restrict area, __global const real* restrict face_x,
    __global const real* restrict face_y, __global real* restrict out_left,
    __global real* restrict out_right, __global real* restrict out_top,
    __global real* restrict out_bottom, real dt) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  flow_local_inertial_cell_interior(x, y, W, kind, depth, area, face_x, face_y, out_left, out_right,
                                    out_top, out_bottom, dt);
}

/* The shallow-water scheme (shallow_water.h): one work-item per padded cell (rows 0 .. H - 1);
 * each writes its outflows and, for an active cell, its new unit discharges into the second
 * buffers the host then swaps. */
__kernel void flow_shallow_water(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict q_x,
    __global const real* restrict q_y, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict area, real dt, FlowParams p, __global real* restrict out_left,
    __global real* restrict out_right, __global real* restrict out_top,
    __global real* restrict out_bottom, __global real* restrict q_x_new,
    __global real* restrict q_y_new) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  shallow_water_cell(x, y, W, H, kind, bed, depth, q_x, q_y, manning, dx, dy, area, dt, p, out_left,
                     out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* The velocities the shallow-water faces read (shallow_water_flow_velocity_cell), every padded
 * cell, into u, v: scratch for flow_shallow_water_interior and flow_shallow_water_muscl_interior,
 * on CPU devices. */
__kernel void flow_shallow_water_velocities(int W, int H, __global const real* restrict depth,
                                            __global const real* restrict q_x,
                                            __global const real* restrict q_y, FlowParams p,
                                            __global real* restrict u, __global real* restrict v) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  shallow_water_flow_velocity_cell(x, y, W, depth, q_x, q_y, p.dry_depth, u, v);
}

/* The shallow-water scheme on rows 1 .. H - 2 (shallow_water_cell_interior) from the velocities
 * flow_shallow_water_velocities wrote: no clamping, and no velocity computed five times, so
 * PoCL vectorises it across work-items on CPU devices (flow_shallow_water, whose velocities
 * LLVM's SLP pass packs in pairs, does not). The host runs it on CPU devices, with
 * flow_shallow_water on rows 0 and H - 1; on other devices flow_shallow_water on every row. */
__kernel void flow_shallow_water_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict q_x,
    __global const real* restrict q_y, __global const real* restrict u,
    __global const real* restrict v, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict area, real dt, FlowParams p, __global real* restrict out_left,
    __global real* restrict out_right, __global real* restrict out_top,
    __global real* restrict out_bottom, __global real* restrict q_x_new,
    __global real* restrict q_y_new) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  shallow_water_cell_interior(x, y, W, kind, bed, depth, q_x, q_y, u, v, manning, dx, dy, area, dt,
                              p, out_left, out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* The shallow-water scheme's second order (flow.order = 2, shallow_water.h): a stage of Heun's
 * method with MUSCL faces, one work-item per padded cell of any row (on CPU devices the two
 * first and two last rows, flow_shallow_water_muscl_interior the others);
 * `combine` 0 for the first stage, 1 for the second (averaged into what out_* and q_*_new
 * hold). */
__kernel void flow_shallow_water_muscl(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict q_x,
    __global const real* restrict q_y, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict area, real dt, FlowParams p, int combine,
    __global real* restrict out_left, __global real* restrict out_right,
    __global real* restrict out_top, __global real* restrict out_bottom,
    __global real* restrict q_x_new, __global real* restrict q_y_new) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  shallow_water_muscl_cell(x, y, W, H, kind, bed, depth, q_x, q_y, manning, dx, dy, area, dt, p,
                           combine, out_left, out_right, out_top, out_bottom, q_x_new, q_y_new);
}

/* A stage of the second order on rows 2 .. H - 3 (shallow_water_muscl_cell_interior) from the
 * velocities flow_shallow_water_velocities wrote for the stage's state: no clamping and no
 * velocity computed nine times, so PoCL vectorises it across work-items on CPU devices
 * (flow_shallow_water_muscl does not). The host runs it on CPU devices, with
 * flow_shallow_water_muscl on rows 0, 1, H - 2 and H - 1; elsewhere flow_shallow_water_muscl
 * on every row. */
__kernel void flow_shallow_water_muscl_interior(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict bed,
    __global const real* restrict depth, __global const real* restrict q_x,
    __global const real* restrict q_y, __global const real* restrict u,
    __global const real* restrict v, __global const real* restrict manning,
    __global const real* restrict dx, __global const real* restrict dy,
    __global const real* restrict area, real dt, FlowParams p, int combine,
    __global real* restrict out_left, __global real* restrict out_right,
    __global real* restrict out_top, __global real* restrict out_bottom,
    __global real* restrict q_x_new, __global real* restrict q_y_new) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W)) return;
  shallow_water_muscl_cell_interior(x, y, W, H, kind, bed, depth, q_x, q_y, u, v, manning, dx, dy,
                                    area, dt, p, combine, out_left, out_right, out_top, out_bottom,
                                    q_x_new, q_y_new);
}

/* The depth after Heun's first stage (shallow_water_stage_depth_cell), every padded cell. */
__kernel void flow_shallow_water_stage_depth(
    int W, int H, __global const uchar* restrict kind, __global const real* restrict depth,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global const real* restrict area, real dt, __global real* restrict depth_stage) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  if (ERODEM_PAST_ROW(x, W) || y >= H) return;
  shallow_water_stage_depth_cell(x, y, W, H, kind, depth, f_left, f_right, f_top, f_bottom, area,
                                 dt, depth_stage);
}
