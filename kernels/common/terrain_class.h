/* erodem — terrain classes (issue 18, docs/model.md section 3.12): every active cell is snow,
 * water, rock, mud or grass by a rule on its bed elevation, slope, wetness and snow pack, and
 * each class may carry its own Manning n, talus angle, Green-Ampt soil and erodibility. One
 * sweep, every terrain_classes.interval steps, classifies the cells and writes the class
 * values into the parameter fields the processes read (manning_n, hardness, the infiltration
 * fields, talus_slope); a parameter given as a raster keeps its raster. The viewer draws its
 * terrain_class view with the same rule (viz/src/terrain_class.cpp). */
#ifndef ERODEM_KERNELS_COMMON_TERRAIN_CLASS_H
#define ERODEM_KERNELS_COMMON_TERRAIN_CLASS_H

#include "compat.h"

/* The class codes, as the terrain_class field stores them (as reals). */
#define ERODEM_CLASS_GRASS 0
#define ERODEM_CLASS_MUD 1
#define ERODEM_CLASS_ROCK 2
#define ERODEM_CLASS_SNOW 3
#define ERODEM_CLASS_WATER 4
#define ERODEM_CLASS_COUNT 5

/* The rule's thresholds and the class tables (terrain_class_params_of,
 * kernels/cell_params.hpp). A table row holds, by class code, the value a class's cells take:
 * the class's own where terrain_classes.<class> gives one, else the uniform parameter. */
ERODEM_PARAMS_BEGIN(TerrainClassParams)
  real snow_depth;     /* a cell whose pack (snow water equivalent) exceeds this is snow (m) */
  real snow_line;      /* ... as is one whose bed lies above this (m; the largest real: none) */
  real water_wetness;  /* a cell whose wetness exceeds this is water (m) */
  real rock_slope;     /* a cell steeper than this is rock (m/m) ... */
  real rock_elevation; /* ... where its bed lies above this (m; the lowest real: anywhere) */
  real mud_wetness;    /* a cell whose wetness exceeds this is mud (m) */
  real manning_n[ERODEM_CLASS_COUNT];       /* Manning n (s m^-1/3) */
  real hardness[ERODEM_CLASS_COUNT];        /* erodibility R (1) */
  real ksat[ERODEM_CLASS_COUNT];            /* K_sat (m/s) */
  real suction_deficit[ERODEM_CLASS_COUNT]; /* psi delta theta (m) */
  real store[ERODEM_CLASS_COUNT];           /* L delta theta (m) */
  real talus_slope[ERODEM_CLASS_COUNT];     /* tan of the talus angle (1) */
  /* 1: the tables write the field (some class gives a value and no raster holds it) */
  int set_manning;
  int set_hardness;
  int set_ksat;
  int set_soil; /* infiltration_suction_deficit and infiltration_store */
  int set_talus;
  int classify; /* per step: 1 classify, then write; 0 write from the classes the field holds */
ERODEM_PARAMS_END(TerrainClassParams)

ERODEM_BEGIN_NAMESPACE

/* The slope of the bed (m/m) at a cell of bed b from its neighbours' beds b_l, b_r, b_t, b_b
 * (has_*: the neighbour is an active cell), dist_x and dist_t, dist_b (m) away: the gradient by
 * central differences over the active neighbours, one-sided where one of a pair is missing,
 * 0 along an axis with neither. The initial snow pack's max_slope uses it too. */
ERODEM_FN real bed_slope_cell(real b, real b_l, real b_r, real b_t, real b_b, int has_l, int has_r,
                              int has_t, int has_b, real dist_x, real dist_t, real dist_b) {
  const real run_x = (has_l ? dist_x : (real)0) + (has_r ? dist_x : (real)0);
  const real run_y = (has_t ? dist_t : (real)0) + (has_b ? dist_b : (real)0);
  const real gx = run_x > (real)0 ? ((has_r ? b_r : b) - (has_l ? b_l : b)) / run_x : (real)0;
  const real gy = run_y > (real)0 ? ((has_b ? b_b : b) - (has_t ? b_t : b)) / run_y : (real)0;
  return sqrt(gx * gx + gy * gy);
}

/* The class of a cell with bed elevation `bed` (m), slope (m/m), wetness (m, the running mean
 * of its depth) and snow pack (m of water equivalent); the first rule that holds:
 *   snow   the pack exceeds snow_depth, or the bed lies above snow_line;
 *   water  the wetness exceeds water_wetness (water that stays: rivers, lakes);
 *   rock   the slope exceeds rock_slope where the bed lies above rock_elevation;
 *   mud    the wetness exceeds mud_wetness (ground that stays wet);
 *   grass  everything else. */
ERODEM_FN int terrain_class_of(real bed, real slope, real wetness, real snow,
                               ERODEM_P(TerrainClassParams) p) {
  if (snow > p.snow_depth || bed > p.snow_line) return ERODEM_CLASS_SNOW;
  if (wetness > p.water_wetness) return ERODEM_CLASS_WATER;
  if (slope > p.rock_slope && bed > p.rock_elevation) return ERODEM_CLASS_ROCK;
  if (wetness > p.mud_wetness) return ERODEM_CLASS_MUD;
  return ERODEM_CLASS_GRASS;
}

/* The class sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both backends'
 * loops (the generic sweep "terrain_class": kernels/cpu/sweeps.cpp,
 * kernels/opencl/terrain_class.cl). On an active cell: with p.classify, its class by
 * terrain_class_of into `cls`, else the class `cls` holds; then the tables' values of that
 * class into the parameter fields the tables write (set_*). Other cells keep everything. */
ERODEM_FN void terrain_class_sweep_cell(
    int x, int y, int W, GLOBAL const erodem_kind_t* kind, GLOBAL const real* dx,
    GLOBAL const real* dy, GLOBAL const real* bed, GLOBAL const real* wetness,
    GLOBAL const real* snow, GLOBAL real* cls, GLOBAL real* manning, GLOBAL real* hardness,
    GLOBAL real* ksat, GLOBAL real* suction_deficit, GLOBAL real* store, GLOBAL real* talus,
    GLOBAL const real* area, real dt, ERODEM_P(TerrainClassParams) p) {
  (void)area;
  (void)dt;
  const int i = x + y * W;
  if (!((x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE))) return;
  int k;
  if (p.classify) {
    const real slope =
        bed_slope_cell(bed[i], bed[i - 1], bed[i + 1], bed[i - W], bed[i + W],
                       kind[i - 1] == ERODEM_CELL_ACTIVE, kind[i + 1] == ERODEM_CELL_ACTIVE,
                       kind[i - W] == ERODEM_CELL_ACTIVE, kind[i + W] == ERODEM_CELL_ACTIVE, dx[y],
                       centre_distance_y(dy, y - 1), centre_distance_y(dy, y));
    k = terrain_class_of(bed[i], slope, wetness[i], snow[i], p);
    cls[i] = (real)k;
  } else {
    const int held = (int)cls[i];
    k = held < 0 ? 0 : held >= ERODEM_CLASS_COUNT ? ERODEM_CLASS_COUNT - 1 : held;
  }
  if (p.set_manning) manning[i] = p.manning_n[k];
  if (p.set_hardness) hardness[i] = p.hardness[k];
  if (p.set_ksat) ksat[i] = p.ksat[k];
  if (p.set_soil) {
    suction_deficit[i] = p.suction_deficit[k];
    store[i] = p.store[k];
  }
  if (p.set_talus) talus[i] = p.talus_slope[k];
}

ERODEM_END_NAMESPACE

#endif
