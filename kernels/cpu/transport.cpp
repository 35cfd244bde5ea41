// CPU loops of the transport process: kernels/common/transport.h over the interior cells;
// the active ones take the new sediment (the conservative scheme's in place, rows_in_place),
// the others keep theirs. Per-cell tallies go to a row buffer summed after the row (sum_row),
// so the cell loops vectorise.
#include "common/transport.h"

#include <vector>

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_transport(Real dt, StepTally& tally) {
  const Kind* kind = kind_.data();
  const Real *sediment = sediment_.data(), *area = area_.data();
  const int W = W_, H = H_;
  if (params_.transport.scheme == TransportScheme::conservative) {
    // the new sediment in place (rows_in_place): each cell reads its neighbours' old sediment
    const Real *depth_flow = depth_next_.data(), *fl = flux_[0].data(), *fr = flux_[1].data(),
               *ft = flux_[2].data(), *fb = flux_[3].data();
    rows_in_place(sediment_.data(), [=](int y, Real* sediment_new) {
      const Real step = dt;
      Real* out = tally_rows(2);
      Real* given = out + W;
      ERODEM_IVDEP
      for (int x = 1; x < W - 1; ++x)
        cell::transport_conservative_sweep_cell(x, y, W, kind, sediment, depth_flow, fl, fr, ft, fb,
                                                area, step, sediment_new + x, out + x, given + x);
      row_sums_a_[y] = sum_row(out, static_cast<std::size_t>(W));
      row_sums_b_[y] = sum_row(given, static_cast<std::size_t>(W));
    });
    tally.sediment_out += sum_rows(row_sums_a_);
    tally.sediment_exchanged += sum_rows(row_sums_b_);
    return;
  }
  // semi-Lagrangian: the departure points may lie rows away, so into the second buffer
  Real* sediment_out = sediment_next_.data();
  const Real *u = velocity_x_.data(), *v = velocity_y_.data(), *dx = dx_.data(), *dy = dy_.data();
  const int periodic = periodic_ ? 1 : 0;
  for_rows(1, H - 1, [=](int y) {
    const Real step = dt;
    double change_row = 0.0;
    for (int x = 1; x < W - 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W;
      if (kind[i] != ERODEM_CELL_ACTIVE) continue;
      sediment_out[i] =
          cell::transport_semi_lagrangian_cell(x, y, W, H, sediment, u, v, dx, dy, step, periodic);
      change_row += (static_cast<double>(sediment_out[i]) - sediment[i]) * area[y];
    }
    row_sums_a_[y] = change_row;
  });
  tally.transport_change += sum_rows(row_sums_a_);
  std::swap(sediment_, sediment_next_);
}

template void CpuBackend<float>::run_transport(float, StepTally&);
template void CpuBackend<double>::run_transport(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
