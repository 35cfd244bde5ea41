// CPU loop of the erosion process: kernels/common/erosion.h over the active cells.
#include "common/erosion.h"

#include <limits>

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_erosion(Real dt) {
  const auto& e = params_.erosion;
  const Real kc = static_cast<Real>(e.sediment_capacity), ks = static_cast<Real>(e.dissolving_rate),
             kd = static_cast<Real>(e.deposition_rate), tilt = static_cast<Real>(e.min_tilt),
             dmin = static_cast<Real>(e.min_depth);
  const Real bedrock = e.bedrock_level ? static_cast<Real>(*e.bedrock_level)
                                       : -std::numeric_limits<Real>::infinity();
  for_rows(1, H_ - 1, [&](int y) {
    for (int x = 1; x < W_ - 1; ++x) {
      if (kind_[at(x, y)] != ERODEM_CELL_ACTIVE) continue;
      cell::erosion_cell(x, y, W_, kind_.data(), bed_.data(), bed_next_.data(), sediment_.data(),
                         depth_.data(), velocity_x_.data(), velocity_y_.data(), hardness_.data(),
                         dx_.data(), dy_.data(), dt, kc, ks, kd, tilt, dmin, bedrock);
    }
  });
  std::swap(bed_, bed_next_);
}

template void CpuBackend<float>::run_erosion(float);
template void CpuBackend<double>::run_erosion(double);

}  // namespace erodem
