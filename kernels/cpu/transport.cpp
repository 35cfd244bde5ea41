// CPU loops of the transport process: kernels/common/transport.h over the active cells.
#include "common/transport.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_transport(Real dt, StepTally& tally) {
  if (params_.transport.scheme == TransportScheme::conservative) {
    for_rows(1, H_ - 1, [&](int y) {
      double out_row = 0.0;
      for (int x = 1; x < W_ - 1; ++x) {
        if (kind_[at(x, y)] != ERODEM_CELL_ACTIVE) continue;
        Real out = 0;
        cell::transport_conservative_cell(x, y, W_, kind_.data(), sediment_.data(),
                                          sediment_next_.data(), depth_next_.data(),
                                          flux_[0].data(), flux_[1].data(), flux_[2].data(),
                                          flux_[3].data(), area_.data(), dt, &out);
        out_row += out;
      }
      row_sums_a_[y] = out_row;
    });
    tally.sediment_out += sum_rows(row_sums_a_);
  } else {
    for_rows(1, H_ - 1, [&](int y) {
      double change_row = 0.0;
      for (int x = 1; x < W_ - 1; ++x) {
        const auto i = at(x, y);
        if (kind_[i] != ERODEM_CELL_ACTIVE) continue;
        sediment_next_[i] =
            cell::transport_semi_lagrangian_cell(x, y, W_, H_, sediment_.data(), velocity_x_.data(),
                                                 velocity_y_.data(), dx_.data(), dy_.data(), dt);
        change_row += (static_cast<double>(sediment_next_[i]) - sediment_[i]) * area_[y];
      }
      row_sums_a_[y] = change_row;
    });
    tally.transport_change += sum_rows(row_sums_a_);
  }
  std::swap(sediment_, sediment_next_);
}

template void CpuBackend<float>::run_transport(float, StepTally&);
template void CpuBackend<double>::run_transport(double, StepTally&);

}  // namespace erodem
