/* erodem OpenCL — boundary process: kernels/common/boundary.h on the halo cells (the CPU loop
 * of kernels/cpu/boundary.cpp). Only indexing here; the formulas live in the common header. */
#pragma OPENCL FP_CONTRACT OFF
#include "boundary.h"

/* One work-item per halo cell: ids [0, W-2) the north row, then the south row, then the west
 * column and the east column, H each (the cells the CPU loops visit). The north and south rows
 * only where they are the grid's ghost rows (`north`, `south`), whose corners keep theirs: in a
 * band of an MPI run they may be halo rows, whose ghost columns it fills. */
__kernel void boundary_fill(int W, int H, __global const uchar* restrict kind,
                            __global real* restrict bed, __global real* restrict depth,
                            __global real* restrict sediment, BoundaryParams p, int north,
                            int south) {
  const int id = (int)get_global_id(0);
  const int nxi = W - 2;
  int x, y;
  if (id < nxi) {
    if (!north) return;
    x = 1 + id;
    y = 0;
  } else if (id < 2 * nxi) {
    if (!south) return;
    x = 1 + id - nxi;
    y = H - 1;
  } else if (id < 2 * (nxi + H)) {
    x = id < 2 * nxi + H ? 0 : W - 1;
    y = id - 2 * nxi - (x == 0 ? 0 : H);
    /* the ghost columns on every row but the grid's ghost rows (their corners keep theirs): on
     * a band's halo rows too, as its neighbour fills them (process_table.cpp exact_in_band) */
    if ((y == 0 && north) || (y == H - 1 && south)) return;
  } else {
    return;
  }
  boundary_fill_cell(x, y, W, H, kind, bed, depth, sediment, p);
}

/* The generic sweep "boundary_level" (a stage hydrograph): one work-item per padded cell of rows
 * 1 .. H - 2, boundary_level_sweep_cell; no tallies (the arguments of every generic kernel). */
__kernel void boundary_level(int W, int H, __global const uchar* restrict kind,
                             __global const real* restrict bed, __global real* restrict depth,
                             __global real* restrict sediment, __global const real* restrict area,
                             real dt, BoundaryParams p, __global acc_t* restrict partials,
                             int stride) {
  ERODEM_UNTALLIED_CELL(x, y);
  boundary_level_sweep_cell(x, y, W, kind, bed, depth, sediment, area, dt, p);
}

/* The halo exchange of boundary.periodic_x (process.hpp halo_fields; the CPU's
 * copy_periodic_columns): one work-item per padded row, ghost column 0 takes column W - 2 and
 * ghost column W - 1 column 1. */
__kernel void halo_periodic_x(int W, int H, __global real* restrict f) {
  const int y = (int)get_global_id(0);
  if (y >= H) return;
  f[y * W] = f[y * W + W - 2];
  f[y * W + W - 1] = f[y * W + 1];
}
