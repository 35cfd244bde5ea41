// CPU loops of the sources process (rain, point/line inflows): kernels/common/sources.h
// (evaporation runs through the generic loop of sweeps.cpp).
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
    if (!holds(p.cell)) continue;  // another band's (MPI)
    const auto i = padded(p.cell);
    const int y = static_cast<int>(i / static_cast<std::size_t>(W_));
    depth_[i] += static_cast<Real>(p.volume / static_cast<double>(area_[y]));
    if (p.sediment != 0)
      sediment_[i] += static_cast<Real>(p.sediment / static_cast<double>(area_[y]));
  }
}

template void CpuBackend<float>::run_sources(const StepInputs&);
template void CpuBackend<double>::run_sources(const StepInputs&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
