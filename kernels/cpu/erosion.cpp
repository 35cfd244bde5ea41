// CPU loop of the erosion process: erosion_sweep_cell (kernels/common/erosion.h) over the
// interior cells, branch-free so the loop vectorises. The eroded and deposited volumes go to
// row buffers summed after the row.
#include "common/erosion.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_erosion(Real dt, StepTally& tally) {
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *depth = depth_.data(), *u = velocity_x_.data(),
             *v = velocity_y_.data(), *hardness = hardness_.data(), *dx = dx_.data(),
             *dy = dy_.data(), *area = area_.data();
  Real *bed_out = bed_next_.data(), *bed_lo = bed_residual_.data(), *sediment = sediment_.data();
  const cell_params::ErosionParams<Real> params = cell_.erosion;
  const int W = W_;
  for_rows(1, H_ - 1, [=](int y) {
    // Locals, not closure members: stores to Real arrays could alias those.
    const Real step = dt;
    const cell_params::ErosionParams<Real> p = params;
    const auto eroded_row = row_scratch(W), deposited_row = row_scratch(W);
    Real *eroded = eroded_row.get(), *deposited = deposited_row.get();
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::erosion_sweep_cell(x, y, W, kind, bed, bed_out, bed_lo, sediment, depth, u, v, hardness,
                               dx, dy, area, step, p, eroded + x, deposited + x);
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
