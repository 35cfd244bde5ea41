// CPU loops of the sources process (rain, point/line inflows): kernels/common/sources.h
// (evaporation runs through the generic loop of sweeps.cpp).
#include "common/sources.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::sources_row(int y, Real dt, Real rate) {
  if (rate != Real(0)) {
    const Kind* kind = kind_.data();
    const Real* factor = rain_factor_.data();
    const int pitch = this->pitch(rain_factor_);
    Real* depth = depth_.data();
    const int W = W_;
    const Real step = dt, r = rate;  // locals: stores to Real arrays could alias members
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::rain_sweep_cell(x, y, W, kind, depth, factor, pitch, step, r);
  }
  const auto first =
      std::lower_bound(point_rows_.begin(), point_rows_.end(), std::pair<int, std::size_t>{y, 0});
  for (auto it = first; it != point_rows_.end() && it->first == y; ++it)
    add_inflow(step_inputs_.points[it->second]);
}

template <class Real>
void CpuBackend<Real>::add_inflow(const PointSource& p) {
  if (!holds(p.cell)) return;  // another band's (MPI)
  const auto i = padded(p.cell);
  const int y = static_cast<int>(i / static_cast<std::size_t>(W_));
  depth_[i] += static_cast<Real>(p.volume / static_cast<double>(area_[y]));
  if (p.sediment != 0)
    sediment_[i] += static_cast<Real>(p.sediment / static_cast<double>(area_[y]));
}

template <class Real>
void CpuBackend<Real>::run_sources(const StepInputs& in) {
  const Real dt = static_cast<Real>(in.dt);
  const Real rate = static_cast<Real>(in.rain_rate);
  // the rain on every row, then the inflows in the order of the list
  point_rows_.clear();
  for_rows(1, H_ - 1, [=](int y) { sources_row(y, dt, rate); });
  for (const auto& p : in.points) add_inflow(p);
}

template void CpuBackend<float>::run_sources(const StepInputs&);
template void CpuBackend<float>::sources_row(int, float, float);
template void CpuBackend<double>::sources_row(int, double, double);
template void CpuBackend<double>::run_sources(const StepInputs&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
