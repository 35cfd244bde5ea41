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
  const Real *bed = bed_.data(), *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  const Real* wet = wetness_.data();
  // The talus slopes are read only where the classes set them (by_class); otherwise any
  // array of the grid's size stands in, so that no field of zeros is made for them (4 B/cell).
  const Real* talus = cell_.thermal.by_class ? field_storage(FieldId::talus_slope)->data() : wet;
  Real *share = thermal_share_.data(), *bed_lo = bed_residual_.data();
  const cell_params::ThermalParams<Real> params = cell_.thermal;
  const int W = W_;
  for_rows(1, H_ - 1, [=](int y) {
    // Locals, not closure members: stores to Real arrays could alias those.
    const Real step = dt;
    const cell_params::ThermalParams<Real> p = params;
    // the row as row 0 of arrays that start at row y, its kinds as int (as the apply pass below)
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
    const int* k_row = int_kinds_around(y);
    const Real *bed_r = bed + row, *wet_r = wet + row, *talus_r = talus + row, *dx_r = dx + y,
               *dy_r = dy + y, *area_r = area + y;
    Real* share_r = share + row;
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::thermal_share_sweep_cell(x, 0, W, k_row, bed_r, wet_r, talus_r, dx_r, dy_r, area_r,
                                     share_r, step, p);
  });
  exchange_halo({"thermal_share"});  // the apply pass reads the neighbours' shares
  // the new bed in place (rows_in_place): each cell reads its neighbours' old bed
  rows_in_place(bed_.data(), [=](int y, Real* bed_new) {
    const cell_params::ThermalParams<Real> p = params;
    Real* given = tally_rows(1);
    // the row as row 0 of arrays that start at row y (its neighbours at -W and +W), its kinds
    // as int (int_kinds_around): the same values, the same operations
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * W;
    const int* k_row = int_kinds_around(y);
    const Real *bed_r = bed + row, *wet_r = wet + row, *talus_r = talus + row,
               *share_r = share + row, *dx_r = dx + y, *dy_r = dy + y, *area_r = area + y;
    Real* bed_lo_r = bed_lo + row;
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::thermal_apply_sweep_cell(x, 0, W, k_row, bed_r, bed_lo_r, wet_r, talus_r, share_r, dx_r,
                                     dy_r, area_r, p, bed_new + x, given + x);
    row_sums_a_[y] = sum_row(given, static_cast<std::size_t>(W));
  });
  tally.thermal_moved += sum_rows(row_sums_a_);
}

template void CpuBackend<float>::run_thermal(float, StepTally&);
template void CpuBackend<double>::run_thermal(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
