// CPU loop of the water process: kernels/common/water.h over the active cells.
#include "common/water.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_water(Real dt, StepTally& tally) {
  const Real d_min = static_cast<Real>(params_.numerics.velocity_min_depth);
  for_rows(1, H_ - 1, [&](int y) {
    double exchange_row = 0.0, clipped_row = 0.0;
    for (int x = 1; x < W_ - 1; ++x) {
      if (kind_[at(x, y)] != ERODEM_CELL_ACTIVE) continue;
      Real exchange = 0, clipped = 0;
      cell::water_update_cell(x, y, W_, kind_.data(), depth_.data(), depth_next_.data(),
                              flux_[0].data(), flux_[1].data(), flux_[2].data(), flux_[3].data(),
                              dx_.data(), dy_.data(), area_.data(), velocity_x_.data(),
                              velocity_y_.data(), dt, d_min, &exchange, &clipped);
      exchange_row += exchange;
      clipped_row += clipped;
    }
    row_sums_a_[y] = exchange_row;
    row_sums_b_[y] = clipped_row;
  });
  tally.boundary_water_out += static_cast<double>(dt) * sum_rows(row_sums_a_);
  tally.clipped += sum_rows(row_sums_b_);
  // depth_next_ keeps the depth the flow step saw: conservative transport needs it.
  std::swap(depth_, depth_next_);
}

template void CpuBackend<float>::run_water(float, StepTally&);
template void CpuBackend<double>::run_water(double, StepTally&);

}  // namespace erodem
