// CPU loop of the water process: kernels/common/water.h over the interior cells (the cell
// function leaves non-active cells as they are). Per-cell tallies go to a row buffer summed
// after the row, so the cell loop itself vectorises.
#include "common/water.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::water_row(int y, Real dt, const std::array<const Real*, 4>& out) {
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *depth = depth_.data(), *fl = out[0], *fr = out[1], *ft = out[2],
             *fb = out[3];
  const Real *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  Real *depth_out = depth_next_.data(), *u = velocity_x_.data(), *v = velocity_y_.data();
  // Locals, not members: stores to Real arrays could alias those.
  const Real step = dt;
  const cell_params::WaterParams<Real> p = cell_.water;
  const int W = W_;
  Real* cl = tally_rows(2);  // the clipped and the given volumes of the row's cells
  Real* gv = cl + W;
  // The row's cells are passed as row 0 of arrays that start at row y (its neighbours at -W
  // and +W, inside the fields), its kinds as int (int_kinds_around): the same values, the same
  // operations.
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
  const int* k_row = int_kinds_around(y);
  const Real *bed_r = bed + row, *depth_r = depth + row, *fl_r = fl + row, *fr_r = fr + row,
             *ft_r = ft + row, *fb_r = fb + row, *dx_r = dx + y, *dy_r = dy + y, *area_r = area + y;
  Real *depth_out_r = depth_out + row, *u_r = u + row, *v_r = v + row;
  ERODEM_IVDEP
  for (int x = 1; x < W - 1; ++x) {
    Real exchange;  // unused here (below), so the compiler drops it from the loop
    cell::water_update_cell(x, 0, W, k_row, bed_r, depth_r, depth_out_r, fl_r, fr_r, ft_r, fb_r,
                            dx_r, dy_r, area_r, u_r, v_r, step, p, &exchange, cl + x, gv + x);
  }
  // The exchange through the domain's faces, of the cells beside a ghost or a wall only (it is
  // +0 at every other cell): the bits of sum_row over the whole row (sum_row_at).
  const std::size_t e0 = static_cast<std::size_t>(edge_row_[static_cast<std::size_t>(y)]),
                    e1 = static_cast<std::size_t>(edge_row_[static_cast<std::size_t>(y) + 1]);
  row_sums_a_[y] = sum_row_at(edge_x_.data() + e0, e1 - e0, [&](int x) {
    return cell::water_exchange_cell(static_cast<int>(row + x), W, kind, fl, fr, ft, fb);
  });
  row_sums_b_[y] = sum_row(cl, static_cast<std::size_t>(W));
  row_sums_c_[y] = sum_row(gv, static_cast<std::size_t>(W));
}

template <class Real>
void CpuBackend<Real>::book_water_rows(Real dt, StepTally& tally) {
  tally.boundary_out += static_cast<double>(dt) * sum_rows(row_sums_a_);
  tally.clipped += sum_rows(row_sums_b_);
  tally.water_exchanged += sum_rows(row_sums_c_);
}

template <class Real>
void CpuBackend<Real>::run_water(Real dt, StepTally& tally) {
  const std::array<const Real*, 4> out{flux_[0].data(), flux_[1].data(), flux_[2].data(),
                                       flux_[3].data()};
  for_rows(1, H_ - 1, [&](int y) { water_row(y, dt, out); });
  book_water_rows(dt, tally);
  // depth_next_ keeps the depth the water update started from (after this step's sources):
  // conservative transport needs it.
  std::swap(depth_, depth_next_);
}

template void CpuBackend<float>::run_water(float, StepTally&);
template void CpuBackend<float>::water_row(int, float, const std::array<const float*, 4>&);
template void CpuBackend<double>::water_row(int, double, const std::array<const double*, 4>&);
template void CpuBackend<float>::book_water_rows(float, StepTally&);
template void CpuBackend<double>::book_water_rows(double, StepTally&);
template void CpuBackend<double>::run_water(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
