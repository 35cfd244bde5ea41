// CPU loop of the erosion process: kernels/common/erosion.h over the interior cells; the
// active ones take the new bed, residual and sediment, the others keep theirs (branch-free, so
// the loop vectorises). The eroded and deposited volumes go to row buffers summed after the
// row.
#include "common/erosion.h"

#include <limits>

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_erosion(Real dt, StepTally& tally) {
  const auto& e = params_.erosion;
  const Real kc = static_cast<Real>(e.sediment_capacity), ks = static_cast<Real>(e.dissolving_rate),
             kd = static_cast<Real>(e.deposition_rate), tilt = static_cast<Real>(e.min_tilt),
             dmin = static_cast<Real>(e.min_depth);
  const Real bedrock = e.bedrock_level ? static_cast<Real>(*e.bedrock_level)
                                       : -std::numeric_limits<Real>::infinity();
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *depth = depth_.data(), *u = velocity_x_.data(),
             *v = velocity_y_.data(), *hardness = hardness_.data(), *dx = dx_.data(),
             *dy = dy_.data(), *area = area_.data();
  Real *bed_out = bed_next_.data(), *bed_lo = bed_residual_.data(), *sediment = sediment_.data();
  const int W = W_;
  for_rows(1, H_ - 1, [=](int y) {
    const Real step = dt, k_c = kc, k_s = ks, k_d = kd, min_tilt = tilt, min_depth = dmin,
               rock = bedrock, cell_area = area[y];
    const auto eroded_row = row_scratch(W), deposited_row = row_scratch(W);
    Real *eroded = eroded_row.get(), *deposited = deposited_row.get();
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W;
      // unconditional loads: if-convertible
      const Real b_old = bed[i], lo_old = bed_lo[i], s_old = sediment[i];
      Real lo_new, s_new, moved;
      const Real b_new = cell::erosion_cell(x, y, W, kind, bed, bed_lo, sediment, depth, u, v,
                                            hardness, dx, dy, step, k_c, k_s, k_d, min_tilt,
                                            min_depth, rock, &lo_new, &s_new, &moved);
      const bool active = kind[i] == ERODEM_CELL_ACTIVE;
      bed_out[i] = active ? b_new : b_old;
      bed_lo[i] = active ? lo_new : lo_old;
      sediment[i] = active ? s_new : s_old;
      const Real volume = active ? moved * cell_area : Real(0);
      eroded[x] = volume > 0 ? volume : Real(0);
      deposited[x] = volume < 0 ? -volume : Real(0);
    }
    row_sums_a_[y] = sum_row(eroded, static_cast<std::size_t>(W));
    row_sums_b_[y] = sum_row(deposited, static_cast<std::size_t>(W));
  });
  tally.eroded += sum_rows(row_sums_a_);
  tally.deposited += sum_rows(row_sums_b_);
  std::swap(bed_, bed_next_);
}

template void CpuBackend<float>::run_erosion(float, StepTally&);
template void CpuBackend<double>::run_erosion(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
