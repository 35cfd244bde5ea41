/* erodem OpenCL — the reductions: the ledger's tallies and the field statistics of the CPU
 * reference (CpuBackend::stats and the per-row sums of the processes), accumulated in double
 * where the device has cl_khr_fp64 (see reduce.cl). Each work-group writes one partial
 * result; the host combines the partials in group order, so a result does not depend on
 * timing. Work-groups are a power of two of at most ERODEM_REDUCE_MAX work-items; each
 * work-item first walks its cells with a fixed stride. */
#pragma OPENCL FP_CONTRACT OFF
#include "stats.h"
/* acc_t, the tally slots and the cell kernels' group sums: reduce.cl. */

#define ERODEM_REDUCE_MAX 256

/* Sums s[0 .. local size) into s[0], in a fixed tree order. */
static inline void reduce_local_sum(__local acc_t* s) {
  const int l = (int)get_local_id(0);
  for (int stride = (int)get_local_size(0) / 2; stride > 0; stride >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (l < stride) s[l] += s[l + stride];
  }
  barrier(CLK_LOCAL_MEM_FENCE);
}

/* Whether candidate (v, c) beats the best so far (best, best_c): larger, or as large and
 * earlier (the first cell of the maximum, as the CPU's row-order scan finds it). */
static inline int beats(acc_t v, long c, acc_t best, long best_c) {
  if (c < 0) return 0;
  if (best_c < 0) return 1;
  return v > best || (v == best && c < best_c);
}

/* The ledger's tallies of one step: group t sums slot t of the cell kernels' partials
 * (partials[t * groups + g], g < groups; see reduce.cl) into sums[t]. One group per slot. */
__kernel void reduce_tallies(int groups, __global const acc_t* partials, __global acc_t* sums) {
  __local acc_t s[ERODEM_REDUCE_MAX];
  const int l = (int)get_local_id(0), t = (int)get_group_id(0);
  __global const acc_t* p = partials + (long)t * groups;
  acc_t a = 0;
  for (int g = l; g < groups; g += (int)get_local_size(0)) a += p[g];
  s[l] = a;
  reduce_local_sum(s);
  if (l == 0) sums[t] = s[0];
}

/* Sum over the active cells of (after - before) * area (the change of sum(s * area) by the
 * semi-Lagrangian transport). partials[group]. */
__kernel void reduce_change(int W, int H, __global const uchar* kind, __global const real* after,
                            __global const real* before, __global const real* area,
                            __global acc_t* partials) {
  __local acc_t s[ERODEM_REDUCE_MAX];
  const int l = (int)get_local_id(0);
  const int n = W * H;
  acc_t a = 0;
  for (int i = (int)get_global_id(0); i < n; i += (int)get_global_size(0)) {
    const int x = i % W, y = i / W;
    if (x < 1 || y < 1 || x > W - 2 || y > H - 2 || kind[i] != ERODEM_CELL_ACTIVE) continue;
    a += ((acc_t)after[i] - (acc_t)before[i]) * (acc_t)area[y];
  }
  s[l] = a;
  reduce_local_sum(s);
  if (l == 0) partials[get_group_id(0)] = s[0];
}

/* The field statistics over the active cells. Per group: sums[5 g + k] = water, material,
 * sediment volume, max depth, max speed (hypot, as on the CPU; -1 where the group saw no
 * candidate); cells[3 g + k] = the DEM cell (row * nx + col) of the max depth, of the max speed,
 * and the first cell whose state is not physical (-1: none). */
__kernel void field_stats(int W, int H, __global const uchar* kind, __global const real* bed,
                          __global const real* depth, __global const real* sediment,
                          __global const real* velocity_x, __global const real* velocity_y,
                          __global const real* area, __global acc_t* sums, __global long* cells) {
  __local acc_t s_water[ERODEM_REDUCE_MAX], s_material[ERODEM_REDUCE_MAX],
      s_sediment[ERODEM_REDUCE_MAX], s_max_d[ERODEM_REDUCE_MAX], s_max_v[ERODEM_REDUCE_MAX];
  __local long s_arg_d[ERODEM_REDUCE_MAX], s_arg_v[ERODEM_REDUCE_MAX], s_bad[ERODEM_REDUCE_MAX];
  const int l = (int)get_local_id(0);
  acc_t water = 0, material = 0, sed = 0, max_d = -1, max_v = -1;
  long arg_d = -1, arg_v = -1, bad = -1;
  /* group g: rows 1 + g, 1 + g + groups, ...; work-item l: columns 1 + l, 1 + l + local size,
   * ... (each work-item meets its cells in row-major order) */
  for (int y = 1 + (int)get_group_id(0); y <= H - 2; y += (int)get_num_groups(0))
    for (int x = 1 + l; x <= W - 2; x += (int)get_local_size(0)) {
      const int i = x + y * W;
      if (kind[i] != ERODEM_CELL_ACTIVE) continue;
      const real d = depth[i], b = bed[i], sd = sediment[i];
      const acc_t a = (acc_t)area[y];
      const long cell = (long)(y - 1) * (long)(W - 2) + (long)(x - 1);
      if (bad < 0 && !cell_state_ok(b, d, sd)) bad = cell;
      water += (acc_t)d * a;
      material += ((acc_t)b + (acc_t)sd) * a;
      sed += (acc_t)sd * a;
      if ((acc_t)d > max_d) {
        max_d = (acc_t)d;
        arg_d = cell;
      }
      /* the speed's square ranks the cells (products of floats are exact in double); the
       * winner's speed is hypot below, as on the CPU */
      const acc_t vx = (acc_t)velocity_x[i], vy = (acc_t)velocity_y[i];
      const acc_t v = vx * vx + vy * vy;
      if (v > max_v) {
        max_v = v;
        arg_v = cell;
      }
    }
  s_water[l] = water;
  s_material[l] = material;
  s_sediment[l] = sed;
  s_max_d[l] = max_d;
  s_max_v[l] = max_v;
  s_arg_d[l] = arg_d;
  s_arg_v[l] = arg_v;
  s_bad[l] = bad;
  for (int stride = (int)get_local_size(0) / 2; stride > 0; stride >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (l < stride) {
      const int o = l + stride;
      s_water[l] += s_water[o];
      s_material[l] += s_material[o];
      s_sediment[l] += s_sediment[o];
      if (beats(s_max_d[o], s_arg_d[o], s_max_d[l], s_arg_d[l])) {
        s_max_d[l] = s_max_d[o];
        s_arg_d[l] = s_arg_d[o];
      }
      if (beats(s_max_v[o], s_arg_v[o], s_max_v[l], s_arg_v[l])) {
        s_max_v[l] = s_max_v[o];
        s_arg_v[l] = s_arg_v[o];
      }
      if (s_bad[o] >= 0 && (s_bad[l] < 0 || s_bad[o] < s_bad[l])) s_bad[l] = s_bad[o];
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (l == 0) {
    const int g = (int)get_group_id(0);
    sums[5 * g + 0] = s_water[0];
    sums[5 * g + 1] = s_material[0];
    sums[5 * g + 2] = s_sediment[0];
    sums[5 * g + 3] = s_max_d[0];
    const long c = s_arg_v[0];
    acc_t speed = -1;
    if (c >= 0) {
      const int i = (int)(c % (W - 2)) + 1 + ((int)(c / (W - 2)) + 1) * W;
      speed = hypot((acc_t)velocity_x[i], (acc_t)velocity_y[i]);
    }
    sums[5 * g + 4] = speed;
    cells[3 * g + 0] = s_arg_d[0];
    cells[3 * g + 1] = s_arg_v[0];
    cells[3 * g + 2] = s_bad[0];
  }
}
