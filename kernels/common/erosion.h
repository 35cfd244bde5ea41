/* erodem — erosion and deposition with a transport-capacity law (MODEL.md step 4). */
#ifndef ERODEM_KERNELS_COMMON_EROSION_H
#define ERODEM_KERNELS_COMMON_EROSION_H

#include "compat.h"

ERODEM_BEGIN_NAMESPACE

/* Sine of the local bed tilt from central differences of the bed over active neighbours
 * (one-sided at the edge of the active area). */
ERODEM_FN real bed_tilt_sin(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                            GLOBAL const real* bed, GLOBAL const real* dx, GLOBAL const real* dy) {
  const int i = x + y * W;
  const int has_l = kind[i - 1] == ERODEM_CELL_ACTIVE;
  const int has_r = kind[i + 1] == ERODEM_CELL_ACTIVE;
  const int has_t = kind[i - W] == ERODEM_CELL_ACTIVE;
  const int has_b = kind[i + W] == ERODEM_CELL_ACTIVE;
  const real b_l = has_l ? bed[i - 1] : bed[i];
  const real b_r = has_r ? bed[i + 1] : bed[i];
  const real b_t = has_t ? bed[i - W] : bed[i];
  const real b_b = has_b ? bed[i + W] : bed[i];
  const real span_x = (real)(has_l + has_r) * dx[y];
  const real span_y = (real)(has_t + has_b) * dy[y];
  const real gx = span_x > 0 ? (b_r - b_l) / span_x : (real)0;
  const real gy = span_y > 0 ? (b_b - b_t) / span_y : (real)0;
  const real tan2 = gx * gx + gy * gy;
  return sqrt(tan2 / ((real)1 + tan2));
}

/* Transport capacity C (m of bed-equivalent sediment):
 *   C = K_c * max(sin(tilt), sin_min) * |v| * g(d),
 * capacity K_c (s), speed |v| (m/s), g(d) = min(1, d / d_min_erosion) when d_min_erosion
 * (m) > 0, else 1. */
ERODEM_FN real transport_capacity(real capacity_k, real tilt_sin, real min_tilt, real speed,
                                  real depth, real min_depth) {
  const real limiter = min_depth > 0 ? fmin((real)1, depth / min_depth) : (real)1;
  return capacity_k * fmax(tilt_sin, min_tilt) * speed * limiter;
}

/* Erosion / deposition of active padded cell (x, y). If C > s, erode
 * min(1, K_s R dt) (C - s) from bed into suspension, never below `bedrock` (m); else
 * deposit min(1, K_d dt) (s - C). Reads bed (for the tilt) and writes bed_out; updates
 * sediment in place (only this cell's). Rates K_s, K_d (1/s); hardness R in [0, 1]. */
ERODEM_FN void erosion_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                            GLOBAL const real* bed, GLOBAL real* bed_out, GLOBAL real* sediment,
                            GLOBAL const real* depth, GLOBAL const real* velocity_x,
                            GLOBAL const real* velocity_y, GLOBAL const real* hardness,
                            GLOBAL const real* dx, GLOBAL const real* dy, real dt, real capacity_k,
                            real dissolving_rate, real deposition_rate, real min_tilt,
                            real min_depth, real bedrock) {
  const int i = x + y * W;
  const real u = velocity_x[i];
  const real v = velocity_y[i];
  const real speed = sqrt(u * u + v * v);
  const real tilt = bed_tilt_sin(x, y, W, kind, bed, dx, dy);
  const real capacity = transport_capacity(capacity_k, tilt, min_tilt, speed, depth[i], min_depth);
  const real s = sediment[i];
  real b = bed[i];
  real moved;
  if (capacity > s) {
    moved = fmin((real)1, dissolving_rate * hardness[i] * dt) * (capacity - s);
    moved = fmin(moved, fmax((real)0, b - bedrock));
  } else {
    moved = -fmin((real)1, deposition_rate * dt) * (s - capacity);
  }
  bed_out[i] = b - moved;
  sediment[i] = s + moved;
}

ERODEM_END_NAMESPACE

#endif
