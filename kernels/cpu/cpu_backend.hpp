// erodem — the CPU reference backend: the per-cell functions of kernels/common/*.h run over
// a padded raster by OpenMP threads, one row per iteration. Reductions are summed per row
// and then in row order, so results do not depend on the number of threads.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/compat.h"
#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

template <class Real>
class CpuBackend final : public Backend {
 public:
  CpuBackend(const Terrain& terrain, const Params& params);

  std::string name() const override { return "cpu"; }
  std::string device() const override;
  void run(Process p, const StepInputs& in, StepTally& tally) override;
  FieldStats stats() override;
  std::vector<double> field(FieldId id) const override;
  void set_field(FieldId id, const std::vector<double>& values) override;
  HostView host_view(FieldId id) override;

  // One function per process, each in kernels/cpu/<process>.cpp.
  void run_boundary();
  void run_sources(const StepInputs& in);
  void run_flow(Real dt);
  void run_water(Real dt, StepTally& tally);
  void run_erosion(Real dt);
  void run_transport(Real dt, StepTally& tally);
  void run_thermal(Real dt);
  void run_evaporation(Real dt, StepTally& tally);

 private:
  using Kind = cell::erodem_kind_t;
  /// Index of padded cell (x, y).
  std::size_t at(int x, int y) const {
    return static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W_;
  }
  /// Index in the padded raster of DEM cell `cell` (row-major (ny, nx)).
  std::size_t padded(std::int64_t cell) const {
    return at(static_cast<int>(cell % nx_) + 1, static_cast<int>(cell / nx_) + 1);
  }
  /// Calls f(y) for the padded rows [y0, y1) on the backend's threads.
  template <class F>
  void for_rows(int y0, int y1, const F& f) const {
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (int y = y0; y < y1; ++y) f(y);
  }
  /// Sums per-row partial sums in row order (deterministic for any thread count).
  static double sum_rows(const std::vector<double>& rows);
  /// Sums a row of per-cell values in double, in order.
  static double sum_row(const std::vector<Real>& row) {
    double s = 0.0;
    for (Real v : row) s += static_cast<double>(v);
    return s;
  }
  std::vector<Real>* field_storage(FieldId id);

  Params params_;
  int nx_, ny_, W_, H_;
  int threads_;
  std::vector<Kind> kind_;
  std::vector<Real> dx_, dy_, area_;  // per padded row
  std::vector<Real> bed_, bed_next_, bed0_;
  std::vector<Real> depth_, depth_next_;  // after `water`, depth_next_ holds the depth the
                                          // flow step saw (used by conservative transport)
  std::vector<Real> sediment_, sediment_next_;
  std::array<std::vector<Real>, 4> flux_, flux_next_;  // left, right, top, bottom (m^3/s)
  std::vector<Real> velocity_x_, velocity_y_;
  std::vector<Real> hardness_, manning_, wetness_, rain_factor_, thermal_share_;
  std::vector<double> row_sums_a_, row_sums_b_;  // scratch for per-row reductions
};

}  // namespace erodem
