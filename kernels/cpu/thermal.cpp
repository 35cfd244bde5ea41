// CPU loops of the thermal process: the two passes of kernels/common/thermal.h over the
// interior cells, branch-free (inactive cells: share 0, bed kept), so the loops vectorise. The
// volume the cells gave goes to a row buffer summed after the row.
#include "common/thermal.h"

#include <cmath>

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_thermal(Real dt, StepTally& tally) {
  const double pi = 3.14159265358979323846;
  const Real tan_talus = static_cast<Real>(std::tan(params_.thermal.talus_angle * pi / 180.0));
  const Real rate = static_cast<Real>(params_.thermal.rate);
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  Real *share = thermal_share_.data(), *bed_out = bed_next_.data(), *bed_lo = bed_residual_.data();
  const int W = W_;
  for_rows(1, H_ - 1, [=](int y) {
    const Real step = dt, k = rate, tan_t = tan_talus;
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W;
      const Real s = cell::thermal_share_cell(x, y, W, kind, bed, dx, dy, area, step, k, tan_t);
      share[i] = kind[i] == ERODEM_CELL_ACTIVE ? s : Real(0);
    }
  });
  for_rows(1, H_ - 1, [=](int y) {
    const Real tan_t = tan_talus;
    const auto given_row = row_scratch(W);
    Real* given = given_row.get();
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W;
      const Real b_old = bed[i], lo_old = bed_lo[i];  // unconditional loads: if-convertible
      Real lo_new, gave;
      const Real b = cell::thermal_apply_cell(x, y, W, kind, bed, bed_lo, share, dx, dy, area,
                                              tan_t, &lo_new, &gave);
      const bool active = kind[i] == ERODEM_CELL_ACTIVE;
      bed_out[i] = active ? b : b_old;
      bed_lo[i] = active ? lo_new : lo_old;
      given[x] = active ? gave : Real(0);
    }
    row_sums_a_[y] = sum_row(given, static_cast<std::size_t>(W));
  });
  tally.thermal_moved += sum_rows(row_sums_a_);
  std::swap(bed_, bed_next_);
}

template void CpuBackend<float>::run_thermal(float, StepTally&);
template void CpuBackend<double>::run_thermal(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
