// CPU loops of the thermal process: the two passes of kernels/common/thermal.h.
#include "common/thermal.h"

#include <cmath>

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_thermal(Real dt) {
  const double pi = 3.14159265358979323846;
  const Real tan_talus = static_cast<Real>(std::tan(params_.thermal.talus_angle * pi / 180.0));
  const Real rate = static_cast<Real>(params_.thermal.rate);
  for_rows(1, H_ - 1, [&](int y) {
    for (int x = 1; x < W_ - 1; ++x) {
      const auto i = at(x, y);
      thermal_share_[i] =
          kind_[i] == ERODEM_CELL_ACTIVE
              ? cell::thermal_share_cell(x, y, W_, kind_.data(), bed_.data(), dx_.data(),
                                         dy_.data(), area_.data(), dt, rate, tan_talus)
              : Real(0);
    }
  });
  for_rows(1, H_ - 1, [&](int y) {
    for (int x = 1; x < W_ - 1; ++x) {
      const auto i = at(x, y);
      bed_next_[i] =
          kind_[i] == ERODEM_CELL_ACTIVE
              ? cell::thermal_apply_cell(x, y, W_, kind_.data(), bed_.data(), thermal_share_.data(),
                                         dx_.data(), dy_.data(), area_.data(), tan_talus)
              : bed_[i];
    }
  });
  std::swap(bed_, bed_next_);
}

template void CpuBackend<float>::run_thermal(float);
template void CpuBackend<double>::run_thermal(double);

}  // namespace erodem
