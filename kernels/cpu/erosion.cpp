// CPU loop of the erosion process: erosion_sweep_cell (kernels/common/erosion.h) over the
// interior cells, branch-free so the loop vectorises, the bed updated in place
// (rows_in_place). The eroded and deposited volumes go to row buffers summed after the row.
#include "common/erosion.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_erosion(Real dt, StepTally& tally) {
  if (params_.erosion.law == ErosionLaw::physical) return run_erosion_physical(dt, tally);
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *depth = depth_.data(), *u = velocity_x_.data(),
             *v = velocity_y_.data(), *hardness = hardness_.data(), *dx = dx_.data(),
             *dy = dy_.data(), *area = area_.data();
  Real *bed_lo = bed_residual_.data(), *sediment = sediment_.data();
  const cell_params::ErosionParams<Real> params = cell_.erosion;
  const int W = W_;
  rows_in_place(bed_.data(), [=](int y, Real* bed_new) {
    // Locals, not closure members: stores to Real arrays could alias those.
    const Real step = dt;
    const cell_params::ErosionParams<Real> p = params;
    Real* eroded = tally_rows(2);
    Real* deposited = eroded + W;
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::erosion_sweep_cell(x, y, W, kind, bed, bed_lo, sediment, depth, u, v, hardness, dx, dy,
                               area, step, p, bed_new + x, eroded + x, deposited + x);
    row_sums_a_[y] = sum_row(eroded, static_cast<std::size_t>(W));
    row_sums_b_[y] = sum_row(deposited, static_cast<std::size_t>(W));
  });
  tally.eroded += sum_rows(row_sums_a_);
  tally.deposited += sum_rows(row_sums_b_);
}

// The physical law (erosion.h sediment_sweep_cell): the same loop with the soil, Manning n and
// four tallies.
template <class Real>
void CpuBackend<Real>::run_erosion_physical(Real dt, StepTally& tally) {
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *depth = depth_.data(), *u = velocity_x_.data(),
             *v = velocity_y_.data(), *n = manning_.data(), *hardness = hardness_.data(),
             *dx = dx_.data(), *dy = dy_.data(), *area = area_.data();
  Real *bed_lo = bed_residual_.data(), *sediment = sediment_.data(),
       *soil = field_storage(FieldId::soil_thickness)->data();
  const cell_params::SedimentParams<Real> params = cell_.sediment;
  const int W = W_;
  if (row_sums_.size() < 4) row_sums_.resize(4);
  for (auto& r : row_sums_) r.assign(H_, 0.0);
  std::vector<double>* sums = row_sums_.data();
  rows_in_place(bed_.data(), [=](int y, Real* bed_new) {
    // Locals, not closure members: stores to Real arrays could alias those (GCC then leaves
    // the loop scalar).
    const Kind* k_ = kind;
    const Real *b_ = bed, *h_ = depth, *u_ = u, *v_ = v, *n_ = n, *r_ = hardness, *dx_l = dx,
               *dy_l = dy, *a_ = area;
    Real *lo_ = bed_lo, *s_ = sediment, *l_ = soil;
    const Real step = dt;
    const cell_params::SedimentParams<Real> p = params;
    Real* eroded = tally_rows(4);
    Real *deposited = eroded + W, *rock = deposited + W, *bulking = rock + W;
    ERODEM_IVDEP
    for (int x = 1; x < W - 1; ++x)
      cell::sediment_sweep_cell(x, y, W, k_, b_, lo_, s_, l_, h_, u_, v_, n_, r_, dx_l, dy_l, a_,
                                step, p, bed_new + x, eroded + x, deposited + x, rock + x,
                                bulking + x);
    sums[0][y] = sum_row(eroded, static_cast<std::size_t>(W));
    sums[1][y] = sum_row(deposited, static_cast<std::size_t>(W));
    sums[2][y] = sum_row(rock, static_cast<std::size_t>(W));
    sums[3][y] = sum_row(bulking, static_cast<std::size_t>(W));
  });
  tally.eroded += sum_rows(row_sums_[0]);
  tally.deposited += sum_rows(row_sums_[1]);
  tally.eroded_bedrock += sum_rows(row_sums_[2]);
  tally.bed_bulking += sum_rows(row_sums_[3]);
}

template void CpuBackend<float>::run_erosion(float, StepTally&);
template void CpuBackend<double>::run_erosion(double, StepTally&);
template void CpuBackend<float>::run_erosion_physical(float, StepTally&);
template void CpuBackend<double>::run_erosion_physical(double, StepTally&);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
