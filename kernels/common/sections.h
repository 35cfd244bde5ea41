/* erodem — cross-sections and outlets (docs/model.md "Sections"): what crosses one face of the
 * grid, from the same outflows the water update and the transport apply. */
#ifndef ERODEM_KERNELS_COMMON_SECTIONS_H
#define ERODEM_KERNELS_COMMON_SECTIONS_H

#include "transport.h"

ERODEM_BEGIN_NAMESPACE

/* A face as the backends list it: code = 2 * i + axis, with i the padded cell west (axis 0) or
 * north (axis 1) of the face and j = i + 1 or i + W the cell beyond it. */
ERODEM_INLINE int section_face_far(int code, int W) {
  const int i = code >> 1;
  return (code & 1) ? i + W : i + 1;
}

/* The net discharge (m^3/s) through face `code`, positive from i to j (eastwards, southwards):
 * what i gives j less what j gives i, the outflows the water update moves
 * (water_update_cell), so the faces around a region sum to what left it. */
ERODEM_FN real section_face_water(int code, int W, GLOBAL const real* f_left,
                                  GLOBAL const real* f_right, GLOBAL const real* f_top,
                                  GLOBAL const real* f_bottom) {
  const int i = code >> 1, j = section_face_far(code, W);
  return (code & 1) ? f_bottom[i] - f_top[j] : f_right[i] - f_left[j];
}

/* The sediment flux (m^3/s of solid) through face `code`, positive from i to j: each side's
 * outflow through the face times its concentration (sediment over the depth the flow step
 * limited its outflows by, depth_flow), the terms transport_conservative_cell moves. */
ERODEM_FN real section_face_sediment(int code, int W, GLOBAL const real* sediment,
                                     GLOBAL const real* depth_flow, GLOBAL const real* f_left,
                                     GLOBAL const real* f_right, GLOBAL const real* f_top,
                                     GLOBAL const real* f_bottom) {
  const int i = code >> 1, j = section_face_far(code, W);
  const real out_i = (code & 1) ? f_bottom[i] : f_right[i];
  const real out_j = (code & 1) ? f_top[j] : f_left[j];
  return sediment_concentration(sediment[i], depth_flow[i]) * out_i -
         sediment_concentration(sediment[j], depth_flow[j]) * out_j;
}

ERODEM_END_NAMESPACE

#endif
