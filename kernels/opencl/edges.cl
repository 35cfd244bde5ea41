/* erodem OpenCL — the ledger's tallies that only cells beside a ghost have: the water that
 * leaves or enters through the faces with ghosts (water_exchange_cell, kernels/common/water.h)
 * and the sediment carried out with it (transport_boundary_out_cell,
 * kernels/common/transport.h). The CPU loops of kernels/cpu/water.cpp and transport.cpp sum
 * them over every cell; here they run over the list of the active cells with a ghost
 * neighbour (fixed: the cell kinds do not change), so the water and transport kernels need no
 * tally of their own. The list's order (row-major) and the work-group sums make every result
 * independent of timing. */
#pragma OPENCL FP_CONTRACT OFF
/* water.h and transport.h: already included */

/* One work-item per listed cell (the global size is rounded up to whole work-groups; every
 * work-item reaches the group sum): `slot` ERODEM_TALLY_BOUNDARY_OUT sums the water exchange
 * (m^3/s), ERODEM_TALLY_SEDIMENT_OUT the sediment carried out in dt (m^3; sediment and
 * depth_flow as the conservative transport reads them). Group g's sum goes to
 * partials[slot * stride + g]. */
__kernel void edge_tallies(
    int W, __global const uchar* restrict kind, __global const int* restrict cells, int count,
    __global const real* restrict f_left, __global const real* restrict f_right,
    __global const real* restrict f_top, __global const real* restrict f_bottom,
    __global const real* restrict sediment, __global const real* restrict depth_flow, real dt,
    int slot, __global acc_t* restrict partials, int stride) {
  __local real s[ERODEM_CELL_GROUP_MAX];
  __local acc_t s_lanes[ERODEM_TALLY_LANES];
  const int e = (int)get_global_id(0);
  real v = 0;
  if (e < count) {
    const int i = cells[e];
    v = slot == ERODEM_TALLY_BOUNDARY_OUT
            ? water_exchange_cell(i, W, kind, f_left, f_right, f_top, f_bottom)
            : transport_boundary_out_cell(i, W, kind, sediment, depth_flow, f_left, f_right, f_top,
                                          f_bottom, dt);
  }
  cell_group_sum(s, s_lanes, v, partials + slot * stride + (int)get_group_id(0));
}
