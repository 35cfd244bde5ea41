/* erodem — boundary ghosts (MODEL.md "Boundaries"): the state of the halo cells. */
#ifndef ERODEM_KERNELS_COMMON_BOUNDARY_H
#define ERODEM_KERNELS_COMMON_BOUNDARY_H

#include "compat.h"

/* The run constants of the boundary ghosts (boundary_params, kernels/cell_params.cpp). */
ERODEM_PARAMS_BEGIN(BoundaryParams)
  real sea_level;              /* the level of fixed_level edges and of sea nodata cells (m) */
  real sediment_concentration; /* c_b (1): the solid in the water fixed-level ghosts give */
ERODEM_PARAMS_END(BoundaryParams)

ERODEM_BEGIN_NAMESPACE

/* Set bed, depth and sediment of halo cell (x, y) from the edge cell inside it:
 *  - open: bed one cell of the local slope below the edge cell's bed, same depth (free,
 *    zero-gradient outflow), no sediment (it gives no water);
 *  - fixed_level: water surface at sea_level (m) over a bed no higher than the edge's, holding
 *    c_b of its depth as sediment (m of solid), which the water it gives carries in.
 * Walls and corners keep what they have: no water crosses their faces. */
ERODEM_FN void boundary_fill_cell(int x, int y, int W, int H, GLOBAL const erodem_kind_t* kind,
                                  GLOBAL real* bed, GLOBAL real* depth, GLOBAL real* sediment,
                                  ERODEM_P(BoundaryParams) p) {
  const real sea_level = p.sea_level;
  const int i = x + y * W;
  const int k = kind[i];
  if (k != ERODEM_CELL_OPEN && k != ERODEM_CELL_FIXED) return;
  int step = 0; /* index step from the ghost inwards */
  if (x == 0)
    step = 1;
  else if (x == W - 1)
    step = -1;
  else if (y == 0)
    step = W;
  else if (y == H - 1)
    step = -W;
  else
    return; /* interior ghosts (nodata as sea) keep their state */
  const int e = i + step;
  const real b_e = bed[e];
  if (k == ERODEM_CELL_OPEN) {
    const int e2 = e + step; /* inside the padded raster, since W, H >= 3 */
    const int has_inner = kind[e2] == ERODEM_CELL_ACTIVE;
    const real slope_drop = has_inner ? fabs(b_e - bed[e2]) : (real)0;
    bed[i] = b_e - slope_drop;
    depth[i] = depth[e];
    sediment[i] = (real)0;
  } else {
    const real b_g = fmin(b_e, sea_level);
    bed[i] = b_g;
    depth[i] = sea_level - b_g;
    sediment[i] = p.sediment_concentration * (sea_level - b_g);
  }
}

/* With a stage hydrograph (boundary.stage; the generic sweep "boundary_level", after the
 * halo's): a fixed-level cell inside the grid (a sea nodata cell, or one boundary.raster holds
 * at the level) takes the step's level over its bed, depth max(level - bed, 0), holding c_b of
 * it as sediment; every other cell keeps its state. (Without a stage the level is constant and
 * these cells keep what the initial state gave them.) */
ERODEM_FN void boundary_level_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                                         GLOBAL const real* bed, GLOBAL real* depth,
                                         GLOBAL real* sediment, GLOBAL const real* area, real dt,
                                         ERODEM_P(BoundaryParams) p) {
  const int i = x + y * W;
  const int held = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_FIXED);
  const real d = p.sea_level - bed[i] > (real)0 ? p.sea_level - bed[i] : (real)0;
  const real d_old = depth[i], s_old = sediment[i];
  depth[i] = held ? d : d_old;
  sediment[i] = held ? p.sediment_concentration * d : s_old;
  (void)area;
  (void)dt;
}

ERODEM_END_NAMESPACE

#endif
