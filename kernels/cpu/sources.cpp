// CPU loops of the sources process (rain, point/line inflows) and of evaporation:
// kernels/common/sources.h.
#include "common/sources.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_sources(const StepInputs& in) {
  const Real dt = static_cast<Real>(in.dt);
  const Real rate = static_cast<Real>(in.rain_rate);
  if (rate != Real(0)) {
    for_rows(1, H_ - 1, [&](int y) {
      for (int x = 1; x < W_ - 1; ++x) {
        const auto i = at(x, y);
        if (kind_[i] == ERODEM_CELL_ACTIVE)
          depth_[i] = cell::rain_cell(depth_[i], dt, rate, rain_factor_[i]);
      }
    });
  }
  for (const auto& p : in.points) {
    const auto i = padded(p.cell);
    const int y = static_cast<int>(i / static_cast<std::size_t>(W_));
    depth_[i] += static_cast<Real>(p.volume / static_cast<double>(area_[y]));
  }
}

template <class Real>
void CpuBackend<Real>::run_evaporation(Real dt, StepTally& tally) {
  const Real rate = static_cast<Real>(params_.evaporation.rate);
  const Real tau = static_cast<Real>(params_.numerics.wetness_time);
  for_rows(1, H_ - 1, [&](int y) {
    double lost_row = 0.0;
    for (int x = 1; x < W_ - 1; ++x) {
      const auto i = at(x, y);
      if (kind_[i] != ERODEM_CELL_ACTIVE) continue;
      if (rate > Real(0)) {
        Real lost = 0;
        depth_[i] = cell::evaporation_cell(depth_[i], dt, rate, area_[y], &lost);
        lost_row += lost;
      }
      wetness_[i] = cell::wetness_cell(wetness_[i], depth_[i], dt, tau);
    }
    row_sums_a_[y] = lost_row;
  });
  tally.evaporated += sum_rows(row_sums_a_);
}

template void CpuBackend<float>::run_sources(const StepInputs&);
template void CpuBackend<double>::run_sources(const StepInputs&);
template void CpuBackend<float>::run_evaporation(float, StepTally&);
template void CpuBackend<double>::run_evaporation(double, StepTally&);

}  // namespace erodem
