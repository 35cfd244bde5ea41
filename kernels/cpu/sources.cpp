// CPU loops of the sources process (rain, point/line inflows) and of evaporation:
// kernels/common/sources.h.
#include "common/sources.h"

#include <vector>

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_sources(const StepInputs& in) {
  const Real dt = static_cast<Real>(in.dt);
  const Real rate = static_cast<Real>(in.rain_rate);
  if (rate != Real(0)) {
    const Kind* kind = kind_.data();
    const Real* factor = rain_factor_.data();
    Real* depth = depth_.data();
    const int W = W_;
    for_rows(1, H_ - 1, [=](int y) {
      const Real step = dt, r = rate;
      ERODEM_IVDEP
      for (int x = 1; x < W - 1; ++x) cell::rain_sweep_cell(x, y, W, kind, depth, factor, step, r);
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
  const Kind* kind = kind_.data();
  const Real* area = area_.data();
  Real *depth = depth_.data(), *wetness = wetness_.data();
  const cell_params::EvaporationParams<Real> params = cell_.evaporation;
  const int W = W_;
  for_rows(1, H_ - 1, [=](int y) {
    // Locals, not closure members: stores to Real arrays could alias those.
    const Real step = dt;
    const cell_params::EvaporationParams<Real> p = params;
    const auto lost_row = row_scratch(W);
    Real* lost = lost_row.get();
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::evaporation_sweep_cell(x, y, W, kind, depth, wetness, area, step, p, lost + x);
    row_sums_a_[y] = sum_row(lost, static_cast<std::size_t>(W));
  });
  tally.evaporated += sum_rows(row_sums_a_);
}

template void CpuBackend<float>::run_sources(const StepInputs&);
template void CpuBackend<double>::run_sources(const StepInputs&);
template void CpuBackend<float>::run_evaporation(float, StepTally&);
template void CpuBackend<double>::run_evaporation(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
