/* erodem OpenCL — the reductions: the ledger's tallies and the field statistics of the CPU
 * reference (CpuBackend::stats and the per-row sums of the processes), accumulated in double
 * where the device has cl_khr_fp64 (see reduce.cl). Each work-group writes one partial
 * result; the host combines the partials in group order, so a result does not depend on
 * timing. The reduction kernels' work-groups are a power of two of at most ERODEM_REDUCE_MAX
 * work-items, each work-item first walking its cells with a fixed stride; field_stats is a
 * cell kernel (one work-item per cell). gather_cells, at the end, reads single cells. */
#pragma OPENCL FP_CONTRACT OFF
#include "sections.h"
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

/* The ledger's tallies of one step: group t sums slot t of the cell kernels' partials
 * (partials[t * groups + g], g < groups: the stride of the slots; see reduce.cl) into sums[t].
 * One group per slot. */
__kernel void reduce_tallies(int groups, __global const acc_t* restrict partials,
                             __global acc_t* restrict sums) {
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
__kernel void reduce_change(int W, int H, __global const uchar* restrict kind,
                            __global const real* restrict after,
                            __global const real* restrict before,
                            __global const real* restrict area, __global acc_t* restrict partials) {
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

/* The part of field_stats that one work-item does for its group, once the cells' values are
 * in local memory: the group of n work-items starts at column x0 of padded row `row` and
 * writes partial g (see field_stats). ERODEM_GROUP_ONCE: see reduce.cl. */
ERODEM_GROUP_ONCE void field_stats_group(int W, int row, int x0, int n, int g, int material,
                                         __local const real* s_d, __local const real* s_b,
                                         __local const real* s_r, __local const real* s_s,
                                         __local const real* s_u, __local const real* s_v,
                                         __local const int* s_state, __global const real* area,
                                         __global acc_t* sums, __global long* cells) {
  const int last = min(n, W - x0); /* work-items inside the row */
  const acc_t a = (acc_t)area[row];
  const long row_cell = (long)(row - 1) * (long)(W - 2) - 1 + (long)x0; /* cell of local id 0 */
  /* the four sums of cell_tallies_sum, in its order, in one loop: four chains of adds side
   * by side run in the time of one (each waits for its previous add) */
  acc_t water = 0, bed_sum = 0, res = 0, sed = 0;
  const int sum_blocks = last / 8;
  if (sum_blocks > 0 && material) {
    acc8_t w8 = convert_acc8(vload8(0, s_d)), b8 = convert_acc8(vload8(0, s_b)),
           r8 = convert_acc8(vload8(0, s_r)), s8 = convert_acc8(vload8(0, s_s));
    for (int k = 1; k < sum_blocks; ++k) {
      w8 += convert_acc8(vload8(k, s_d));
      b8 += convert_acc8(vload8(k, s_b));
      r8 += convert_acc8(vload8(k, s_r));
      s8 += convert_acc8(vload8(k, s_s));
    }
    water = acc8_total(w8);
    bed_sum = acc8_total(b8);
    res = acc8_total(r8);
    sed = acc8_total(s8);
  } else if (sum_blocks > 0) { /* the depths alone, in the same lanes and order */
    acc8_t w8 = convert_acc8(vload8(0, s_d));
    for (int k = 1; k < sum_blocks; ++k) w8 += convert_acc8(vload8(k, s_d));
    water = acc8_total(w8);
  }
  for (int k = 8 * sum_blocks; k < last; ++k) {
    water += (acc_t)s_d[k];
    if (!material) continue;
    bed_sum += (acc_t)s_b[k];
    res += (acc_t)s_r[k];
    sed += (acc_t)s_s[k];
  }
  /* maxima: the first largest value in local-id (= row) order, active cells only; lane j of
   * the 8-vectors keeps the first largest among the local ids j mod 8 (strictly larger
   * replaces), the lanes are then merged (the largest, the earliest of equals), and the rest after
   * the last multiple of 8 comes in order. The squared speed in acc_t is exact for float
   * velocities, so it ranks the cells as the CPU ranks them. bad: the first state 2. */
  acc_t max_d = -1, max_v = -1;
  long arg_d = -1, arg_v = -1, bad = -1;
  const int blocks = last / 8;
  if (blocks > 0) {
    float8 best_d = (float8)(-1); /* real is float on OpenCL devices */
    acc8_t best_v = (acc8_t)(-1);
    int8 at_d = (int8)(-1), at_v = (int8)(-1), at_bad = (int8)(-1);
    const int8 lane = (int8)(0, 1, 2, 3, 4, 5, 6, 7);
    for (int k = 0; k < blocks; ++k) {
      const int8 state = vload8(k, s_state), id = lane + (int8)(8 * k);
      const int8 act = state != (int8)(0);
      const float8 d8 = vload8(k, s_d);
      const int8 deeper = act & (d8 > best_d);
      best_d = select(best_d, d8, deeper);
      at_d = select(at_d, id, deeper);
      const acc8_t u8 = convert_acc8(vload8(k, s_u)), v8 = convert_acc8(vload8(k, s_v));
      const acc8_t v2 = u8 * u8 + v8 * v8;
      const acc8_mask_t faster = convert_acc8_mask(act) & (v2 > best_v);
      best_v = select(best_v, v2, faster);
      at_v = select(at_v, id, convert_int8(faster));
      at_bad = select(at_bad, id, (state == (int8)(2)) & (at_bad < (int8)(0)));
    }
    /* the lanes merged without branches (they mispredicted): the largest value, then the
     * smallest local id holding it. A lane that never took a cell holds -1 and id -1; one
     * that did holds more than -1 (it took only strictly larger values), never NaN. */
    const float4 d4 = fmax(best_d.lo, best_d.hi);
    const float2 d_pair = fmax(d4.lo, d4.hi);
    const float d_top = fmax(d_pair.x, d_pair.y);
    const acc4_t v4 = fmax(best_v.lo, best_v.hi);
    const acc2_t v_pair = fmax(v4.lo, v4.hi);
    const acc_t v_top = fmax(v_pair.x, v_pair.y);
    const int8 none = (int8)(INT_MAX);
    const int8 cd = select(none, at_d, (best_d == (float8)(d_top)) & (at_d >= (int8)(0)));
    const int8 cv =
        select(none, at_v, convert_int8(best_v == (acc8_t)(v_top)) & (at_v >= (int8)(0)));
    const int8 cb = select(none, at_bad, at_bad >= (int8)(0));
    const int4 cd4 = min(cd.lo, cd.hi), cv4 = min(cv.lo, cv.hi), cb4 = min(cb.lo, cb.hi);
    const int2 cd2 = min(cd4.lo, cd4.hi), cv2 = min(cv4.lo, cv4.hi), cb2 = min(cb4.lo, cb4.hi);
    const int kd = min(cd2.x, cd2.y), kv = min(cv2.x, cv2.y), kb = min(cb2.x, cb2.y);
    if (kd != INT_MAX) max_d = (acc_t)s_d[kd]; /* the cell's own value: -0 stays -0 */
    if (kv != INT_MAX) max_v = v_top;
    arg_d = kd == INT_MAX ? -1 : row_cell + kd;
    arg_v = kv == INT_MAX ? -1 : row_cell + kv;
    bad = kb == INT_MAX ? -1 : row_cell + kb;
  }
  for (int k = 8 * blocks; k < last; ++k) {
    if (s_state[k] == 0) continue;
    if (bad < 0 && s_state[k] == 2) bad = row_cell + k;
    if ((acc_t)s_d[k] > max_d) {
      max_d = (acc_t)s_d[k];
      arg_d = row_cell + k;
    }
    const acc_t vx = (acc_t)s_u[k], vy = (acc_t)s_v[k];
    const acc_t v = vx * vx + vy * vy;
    if (v > max_v) {
      max_v = v;
      arg_v = row_cell + k;
    }
  }
  sums[5 * g + 0] = water * a;
  sums[5 * g + 1] =
      ((bed_sum + res) + sed) * a; /* the bed pair (compensated.h); 0 unless material */
  sums[5 * g + 2] = sed * a;
  sums[5 * g + 3] = max_d;
  sums[5 * g + 4] = max_v;
  cells[3 * g + 0] = arg_d;
  cells[3 * g + 1] = arg_v;
  cells[3 * g + 2] = bad;
}

/* The largest work-group of field_stats in the row launches (the host's stats_local_). */
#define ERODEM_STATS_GROUP_MAX 256

/* The field statistics over the active cells of padded rows 1 .. H - 2. Per work-group g:
 * sums[5 g + k] = water, material, sediment volume, max depth, max squared speed (-1 where
 * the group has no candidate); cells[3 g + k] = the DEM cell (row * nx + col) of the max
 * depth, of the max speed, and the first cell whose state is not physical (-1: none).
 * stats_rows combines them per row. Two launches, the same maxima and cells, the sums in
 * another order:
 *  - whole rows (ERODEM_WHOLE_ROWS, CPU devices): a cell kernel (launch_interior), one
 *    work-item per padded cell in groups of (L, 1) inside one row (L <= ERODEM_CELL_GROUP_MAX),
 *    g = group x + (y - 1) * groups_per_row; the row's tail (its last columns, launched on
 *    their own at an x offset where L does not divide the row: launch_rows) is its last
 *    group. Each work-item stores its cell's values in local memory as they are (floats); one
 *    work-item then sums them in acc_t, in eight lanes (see cell_tallies_sum), and multiplies
 *    by the row's cell area: the area is one number per row (field_stats_group). PoCL runs
 *    that walk as vector loops;
 *  - row launches (GPUs): one work-group of L <= ERODEM_STATS_GROUP_MAX work-items per row,
 *    g = y - 1 (stats_rows sees one group per row). Work-item l walks the row's columns
 *    1 + l, 1 + l + L, ... (neighbouring work-items read neighbouring cells), keeping its own
 *    sums and its first largest values; a tree in local memory then merges the L work-items',
 *    every work-item at work. On an H200 (2026-11-27) a cell kernel with one work-item per
 *    group walking the group's values took half of the step (2.3 of 4.7 ms at 4096^2), and a
 *    tree over every cell (eight trees of 128 values per 128 cells, each level behind a
 *    barrier, 32 KiB of local memory per group) still 0.88 ms, 11 % of the device's copy
 *    bandwidth for its 25 bytes per cell.
 * material = 0 (the host keeps the material and sediment volumes, OpenClBackend::collect):
 * neither the bed, its residual nor the sediment is read; their sums are 0 and a cell's state
 * is its depth's (the host asks for this only while every active cell's bed and sediment are
 * as the last full pass found them: finite). */
__kernel void field_stats(int W, int H, int groups_per_row, int material,
                          __global const uchar* restrict kind, __global const real* restrict bed,
                          __global const real* restrict bed_residual,
                          __global const real* restrict depth,
                          __global const real* restrict sediment,
                          __global const real* restrict velocity_x,
                          __global const real* restrict velocity_y,
                          __global const real* restrict area, __global acc_t* restrict sums,
                          __global long* restrict cells) {
#ifdef ERODEM_WHOLE_ROWS
  __local real s_d[ERODEM_CELL_GROUP_MAX], s_b[ERODEM_CELL_GROUP_MAX], s_r[ERODEM_CELL_GROUP_MAX],
      s_s[ERODEM_CELL_GROUP_MAX], s_u[ERODEM_CELL_GROUP_MAX], s_v[ERODEM_CELL_GROUP_MAX];
  __local int s_state[ERODEM_CELL_GROUP_MAX];
  const int x = (int)get_global_id(0), y = (int)get_global_id(1), l = (int)get_local_id(0);
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  /* Every load unconditional (whole rows: cell i lies in the buffer), then selected: a load
   * under `active` became a masked load and its store two masked stores (vmaskmovps), which
   * took half of the kernel's time on AVX2 (Zen 3 runs a masked store as microcode). */
  const real d = depth[i], u = velocity_x[i], v = velocity_y[i];
  /* inactive cells add +0 and rank below every active cell (depth >= 0, speed^2 >= 0) */
  s_d[l] = active ? d : (real)0;
  s_u[l] = active ? u : (real)0;
  s_v[l] = active ? v : (real)0;
  if (material) {
    const real b = bed[i], r = bed_residual[i], sd = sediment[i];
    s_b[l] = active ? b : (real)0;
    s_r[l] = active ? r : (real)0;
    s_s[l] = active ? sd : (real)0;
    s_state[l] = active ? (cell_state_ok(b, d, sd) ? 1 : 2) : 0; /* 0 ghost, 1 ok, 2 not physical */
  } else {
    s_state[l] = active ? (cell_state_ok((real)0, d, (real)0) ? 1 : 2) : 0;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  /* The group's row and first column from the group's ids, not from x and y: PoCL keeps every
   * work-item's values that are used after a barrier in per-work-item storage, and a 64-bit
   * one (a global id) halves the vector width of the whole kernel (8 -> 4 lanes on AVX2/512:
   * 25 ms -> 21 ms at 4096^2). */
  if (get_local_id(0) == 0)
    field_stats_group(W, (int)(get_group_id(1) + get_global_offset(1)),
                      (int)(get_group_id(0) * get_local_size(0) + get_global_offset(0)),
                      (int)get_local_size(0),
                      (row_tail_launch() ? groups_per_row - 1 : (int)get_group_id(0)) +
                          (int)get_group_id(1) * groups_per_row,
                      material, s_d, s_b, s_r, s_s, s_u, s_v, s_state, area, sums, cells);
#else
  /* The row launch. The maxima as (value, column) pairs: a work-item's columns come in
   * increasing order and only a strictly larger value replaces, so it keeps its first largest;
   * the tree takes the larger value or, between equal ones, the smaller column. That rule is
   * associative, so the result is the row scan's cell with its own value (-0 included). A
   * candidate is an active cell whose value is above -1 (the scan's start: no NaN, no depth of
   * -1 or below); the first bad cell the smallest column. The four sums: each work-item's in
   * column order, then the tree's fixed order (the same bits from run to run for one L, not
   * the whole-rows walk's). Local memory: 56 bytes per work-item (14 KiB at L = 256). */
  __local acc_t s_water[ERODEM_STATS_GROUP_MAX], s_bed[ERODEM_STATS_GROUP_MAX],
      s_res[ERODEM_STATS_GROUP_MAX], s_sed[ERODEM_STATS_GROUP_MAX], s_v2[ERODEM_STATS_GROUP_MAX];
  __local real s_d[ERODEM_STATS_GROUP_MAX];
  __local int s_at_d[ERODEM_STATS_GROUP_MAX], s_at_v[ERODEM_STATS_GROUP_MAX],
      s_bad[ERODEM_STATS_GROUP_MAX];
  const int l = (int)get_local_id(0), L = (int)get_local_size(0);
  const int y = (int)get_global_id(1); /* the padded row */
  (void)H;
  (void)groups_per_row;
  acc_t water = 0, bed_sum = 0, res = 0, sed = 0, best_v2 = -1;
  real best_d = -1;
  int at_d = INT_MAX, at_v = INT_MAX, bad = INT_MAX;
  for (int x = 1 + l; x <= W - 2; x += L) {
    const int i = x + y * W;
    if (kind[i] != ERODEM_CELL_ACTIVE) continue;
    const real d = depth[i];
    real b = 0, sd = 0;
    water += (acc_t)d;
    if (material) {
      b = bed[i];
      sd = sediment[i];
      bed_sum += (acc_t)b;
      res += (acc_t)bed_residual[i];
      sed += (acc_t)sd;
    }
    if (d > best_d) { /* best_d starts at -1: the scan's start */
      best_d = d;
      at_d = x;
    }
    const acc_t u = (acc_t)velocity_x[i], v = (acc_t)velocity_y[i];
    const acc_t v2 = u * u + v * v; /* exact in double for float velocities */
    if (v2 > best_v2) {
      best_v2 = v2;
      at_v = x;
    }
    if (bad == INT_MAX && !cell_state_ok(b, d, sd)) bad = x;
  }
  s_water[l] = water;
  s_bed[l] = bed_sum;
  s_res[l] = res;
  s_sed[l] = sed;
  s_d[l] = best_d;
  s_at_d[l] = at_d;
  s_v2[l] = best_v2;
  s_at_v[l] = at_v;
  s_bad[l] = bad;
  for (int stride = L / 2; stride > 0; stride >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (l < stride) {
      const int o = l + stride;
      s_water[l] += s_water[o];
      s_bed[l] += s_bed[o];
      s_res[l] += s_res[o];
      s_sed[l] += s_sed[o];
      if (s_at_d[o] != INT_MAX && (s_at_d[l] == INT_MAX || s_d[o] > s_d[l] ||
                                   (s_d[o] == s_d[l] && s_at_d[o] < s_at_d[l]))) {
        s_d[l] = s_d[o];
        s_at_d[l] = s_at_d[o];
      }
      if (s_at_v[o] != INT_MAX && (s_at_v[l] == INT_MAX || s_v2[o] > s_v2[l] ||
                                   (s_v2[o] == s_v2[l] && s_at_v[o] < s_at_v[l]))) {
        s_v2[l] = s_v2[o];
        s_at_v[l] = s_at_v[o];
      }
      s_bad[l] = min(s_bad[l], s_bad[o]);
    }
  }
  if (l == 0) {
    const int g = y - 1;
    const long row_cell = (long)(y - 1) * (long)(W - 2) - 1; /* the DEM cell of column 0 */
    const acc_t a = (acc_t)area[y];
    sums[5 * g + 0] = s_water[0] * a;
    sums[5 * g + 1] = ((s_bed[0] + s_res[0]) + s_sed[0]) * a; /* the bed pair (compensated.h) */
    sums[5 * g + 2] = s_sed[0] * a;
    sums[5 * g + 3] = s_at_d[0] == INT_MAX ? (acc_t)(-1) : (acc_t)s_d[0];
    sums[5 * g + 4] = s_at_v[0] == INT_MAX ? (acc_t)(-1) : s_v2[0];
    cells[3 * g + 0] = s_at_d[0] == INT_MAX ? -1 : row_cell + s_at_d[0];
    cells[3 * g + 1] = s_at_v[0] == INT_MAX ? -1 : row_cell + s_at_v[0];
    cells[3 * g + 2] = s_bad[0] == INT_MAX ? -1 : row_cell + s_bad[0];
  }
#endif
}

/* The statistics of each padded row 1 .. H - 2 (r = y - 1 < rows) from the groups_x partials
 * of field_stats in that row, in column order, as the CPU reference's row scan gives them:
 * sums added; a maximum replaced only by a strictly larger one (a later group holds later
 * cells); the first bad cell. Per row: row_sums[7 r + k] = water, material, sediment volume,
 * max depth, max squared speed (-1: no candidate), and the two velocities (m/s, 0 without a
 * candidate) of the cell of the max squared speed, whose speed the host takes with the CPU's
 * hypot (OpenCL's hypot may differ from the C library's by an ulp: NVIDIA's did, and the speed
 * sets the local-inertial time step); row_cells[3 r + k] as cells. One work-item per row, so the
 * host reads one result per row, not per group. */
__kernel void stats_rows(int W, int rows, int groups_x, __global const acc_t* restrict sums,
                         __global const long* restrict cells,
                         __global const real* restrict velocity_x,
                         __global const real* restrict velocity_y,
                         __global acc_t* restrict row_sums, __global long* restrict row_cells) {
  const int r = (int)get_global_id(0);
  if (r >= rows) return;
  acc_t water = 0, material = 0, sed = 0, max_d = -1, max_v = -1;
  long arg_d = -1, arg_v = -1, bad = -1;
  for (int gx = 0; gx < groups_x; ++gx) {
    const int g = gx + r * groups_x;
    water += sums[5 * g + 0];
    material += sums[5 * g + 1];
    sed += sums[5 * g + 2];
    if (cells[3 * g + 0] >= 0 && sums[5 * g + 3] > max_d) {
      max_d = sums[5 * g + 3];
      arg_d = cells[3 * g + 0];
    }
    if (cells[3 * g + 1] >= 0 && sums[5 * g + 4] > max_v) {
      max_v = sums[5 * g + 4];
      arg_v = cells[3 * g + 1];
    }
    if (bad < 0) bad = cells[3 * g + 2];
  }
  acc_t u = 0, v = 0;
  if (arg_v >= 0) {
    const int c = (int)(arg_v % (long)(W - 2)) + 1 + (r + 1) * W;
    u = velocity_x[c];
    v = velocity_y[c];
  }
  row_sums[7 * r + 0] = water;
  row_sums[7 * r + 1] = material;
  row_sums[7 * r + 2] = sed;
  row_sums[7 * r + 3] = max_d;
  row_sums[7 * r + 4] = max_v;
  row_sums[7 * r + 5] = u;
  row_sums[7 * r + 6] = v;
  row_cells[3 * r + 0] = arg_d;
  row_cells[3 * r + 1] = arg_v;
  row_cells[3 * r + 2] = bad;
}

/* Single cells of fields, for the probes of a step and Backend::sample: out[offset + k n + j] =
 * part k (< count <= 6) at the padded cell cells[j] (j < n), the floats as they are; the host
 * converts them to double and composes the bed with its residual as Backend::field does. One
 * work-item per cell. The parts may be one buffer (the host binds any to those past count),
 * so they are not restrict. */
__kernel void gather_cells(int n, int count, __global const int* restrict cells,
                           __global real* restrict out, int offset, __global const real* p0,
                           __global const real* p1, __global const real* p2,
                           __global const real* p3, __global const real* p4,
                           __global const real* p5) {
  const int j = (int)get_global_id(0);
  if (j >= n) return;
  const int c = cells[j];
  __global real* o = out + offset + j;
  if (count > 0) o[0] = p0[c];
  if (count > 1) o[n] = p1[c];
  if (count > 2) o[2 * n] = p2[c];
  if (count > 3) o[3 * n] = p3[c];
  if (count > 4) o[4 * n] = p4[c];
  if (count > 5) o[5 * n] = p5[c];
}

/* The faces of the sections and outlets (sections.h): out[j] = what crosses face codes[j],
 * the water (sediment = 0) or the sediment (1), read with the step's statistics. */
__kernel void section_faces(int n, int W, int sediment, __global const int* restrict codes,
                            __global const real* sed, __global const real* depth_flow,
                            __global const real* f_left, __global const real* f_right,
                            __global const real* f_top, __global const real* f_bottom,
                            __global real* restrict out) {
  const int j = (int)get_global_id(0);
  if (j >= n) return;
  const int c = codes[j];
  out[j] = sediment ? section_face_sediment(c, W, sed, depth_flow, f_left, f_right, f_top, f_bottom)
                    : section_face_water(c, W, f_left, f_right, f_top, f_bottom);
}
