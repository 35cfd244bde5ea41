// erodem — the CPU's generic cell loop (process.hpp SweepInfo::generic): a sweep of the
// process table runs its cell function over the DEM rows with the pointers its uses name, the
// process's parameter struct, and one per-row scratch per tally of the process, summed per row
// and then in row order (as every CPU reduction). The list below is the only CPU code a
// generic sweep needs: its name and its cell function.
#include <fmt/format.h>

#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "common/boundary.h"
#include "common/infiltration.h"
#include "common/shallow_water.h"
#include "common/snow.h"
#include "common/sources.h"
#include "common/terrain_class.h"
#include "cpu/cpu_backend.hpp"
#include "erodem/error.hpp"
#include "erodem/process.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {
namespace {

/// The parameter types of a cell function void(int x, int y, int W, A...).
template <class F>
struct CellSignature;
template <class... A>
struct CellSignature<void (*)(int, int, int, A...)> {
  using Args = std::tuple<A...>;
  static constexpr std::size_t count = sizeof...(A);
  /// The index (in A...) of the parameter struct: the one class-type parameter.
  static constexpr std::size_t params_index() {
    constexpr bool is_class[] = {std::is_class_v<A>...};
    for (std::size_t k = 0; k < count; ++k)
      if (is_class[k]) return k;
    return count;
  }
};

/// One row of a generic sweep: Cell over x = 1 .. W - 2 of row y, with the uses' pointers
/// (`f`, cast to the cell function's parameter types), and tally J of cell x at t[J][x]. The
/// pointers are locals here, so the compiler knows the stores of the cell function leave them.
template <auto Cell, class Args, class real, class P, std::size_t N, std::size_t M,
          std::size_t... I, std::size_t... J>
inline void cell_row(int y, int W, const std::array<void*, N>& f, const real* area, real dt,
                     const P& params, const std::array<real*, M>& t, std::index_sequence<I...>,
                     std::index_sequence<J...>) {
  const std::tuple<std::tuple_element_t<I, Args>...> ptr{
      static_cast<std::tuple_element_t<I, Args>>(f[I])...};
  const std::array<real*, M> tally = t;
  (void)tally;  // none for a sweep without tallies
  const P p = params;
  const real step = dt;
  ERODEM_IVDEP
  for (int x = 1; x < W - 1; ++x)
    Cell(x, y, W, std::get<I>(ptr)..., area, step, p, tally[J] + x...);
}

}  // namespace

template <class Real>
template <auto Cell>
typename CpuBackend<Real>::GenericRows CpuBackend<Real>::cell_rows(const SweepInfo& sweep,
                                                                   Process process, Real dt,
                                                                   Real* depth) {
  using Sig = CellSignature<decltype(Cell)>;
  using Args = typename Sig::Args;
  constexpr std::size_t ip = Sig::params_index();
  static_assert(ip >= 2 && ip < Sig::count, "a cell function takes area, dt and a param struct");
  constexpr std::size_t nf = ip - 2, nt = Sig::count - ip - 1;  // fields, tallies
  using P = std::tuple_element_t<ip, Args>;

  // the pointers of the uses, the parameter struct and the tallies, checked against the table
  const ProcessInfo& info = process_info(process);
  if (sweep.uses.size() != nf || sweep.tallies.size() != nt)
    throw Error(ExitCode::internal,
                fmt::format("sweep '{}': the table lists {} uses and {} tallies, its cell function "
                            "takes {} and {}",
                            sweep.name, sweep.uses.size(), sweep.tallies.size(), nf, nt));
  std::array<void*, nf> fields{};
  for (std::size_t k = 0; k < nf; ++k) {
    // the grid inputs outside the field table (kind, the rain factor, the per-row cell
    // sizes), then the fields
    const std::string name = sweep.uses[k].field;
    if (name == "kind" || name == "dx" || name == "dy") {
      fields[k] = name == "kind" ? static_cast<void*>(kind_.data())
                  : name == "dx" ? static_cast<void*>(dx_.data())
                                 : static_cast<void*>(dy_.data());
      continue;
    }
    if (depth && name == "water_depth") {
      fields[k] = static_cast<void*>(depth);
      continue;
    }
    // The parameters as held, one row where uniform: their cell functions read them at
    // param_index with the pitch of their parameter struct. (The terrain classes write Manning
    // n and hardness only where class_tables says so; the constructor holds those per cell.)
    const FieldId id = field_info(name).id;
    Field* f = id == FieldId::rain_factor ? &rain_factor_
               : id == FieldId::manning_n ? &manning_
               : id == FieldId::hardness  ? &hardness_
                                          : field_storage(id);
    if (!f)
      throw Error(ExitCode::internal,
                  fmt::format("sweep '{}': field '{}' has no storage", sweep.name, name));
    fields[k] = static_cast<void*>(f->data());
  }
  const ParamBytes bytes = cell_params_bytes(cell_, process);
  if (bytes.size != sizeof(P))
    throw Error(ExitCode::internal,
                fmt::format("sweep '{}': the parameter struct of process '{}' has {} bytes, the "
                            "cell function's {}",
                            sweep.name, info.name, bytes.size, sizeof(P)));
  P params;
  std::memcpy(&params, bytes.data, sizeof(P));
  std::array<double StepTally::*, nt> members{};
  for (std::size_t t = 0; t < nt; ++t)
    for (const auto& e : tally_table())
      if (std::string(e.name) == sweep.tallies[t]) members[t] = e.step;
  if (row_sums_.size() < nt) row_sums_.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) row_sums_[t].assign(H_, 0.0);

  GenericRows rows;
  rows.row = [this, fields, params, dt](int y) {
    const int W = W_;
    Real* scratch = tally_rows(static_cast<int>(nt));
    std::array<Real*, nt> t{};
    for (std::size_t k = 0; k < nt; ++k) t[k] = scratch + k * static_cast<std::size_t>(W);
    cell_row<Cell, Args>(y, W, fields, area_.data(), dt, params, t, std::make_index_sequence<nf>{},
                         std::make_index_sequence<nt>{});
    for (std::size_t k = 0; k < nt; ++k)
      row_sums_[k][y] = sum_row(t[k], static_cast<std::size_t>(W));
  };
  rows.book = [this, members](StepTally& tally) {
    for (std::size_t k = 0; k < nt; ++k) tally.*members[k] += sum_rows(row_sums_[k]);
  };
  return rows;
}

template <class Real>
typename CpuBackend<Real>::GenericRows CpuBackend<Real>::generic_rows(const SweepInfo& sweep,
                                                                      Process process, Real dt,
                                                                      Real* depth) {
  using Make = GenericRows (CpuBackend::*)(const SweepInfo&, Process, Real, Real*);
  // Each generic sweep of the process table by its name, with its cell function.
  static const std::pair<const char*, Make> sweeps[] = {
      {"evaporation", &CpuBackend::cell_rows<&cell::evaporation_sweep_cell<Real>>},
      {"snow", &CpuBackend::cell_rows<&cell::snow_sweep_cell<Real>>},
      {"snow_gridded", &CpuBackend::cell_rows<&cell::snow_gridded_sweep_cell<Real>>},
      {"snow_slide_share", &CpuBackend::cell_rows<&cell::snow_slide_share_sweep_cell<Real>>},
      {"snow_slide", &CpuBackend::cell_rows<&cell::snow_slide_sweep_cell<Real>>},
      {"infiltration", &CpuBackend::cell_rows<&cell::infiltration_sweep_cell<Real>>},
      {"boundary_level", &CpuBackend::cell_rows<&cell::boundary_level_sweep_cell<Real>>},
      {"terrain_class", &CpuBackend::cell_rows<&cell::terrain_class_sweep_cell<Real>>},
      {"shallow_water_velocity",
       &CpuBackend::cell_rows<&cell::shallow_water_velocity_sweep_cell<Real>>},
  };
  for (const auto& [name, make] : sweeps)
    if (std::string(name) == sweep.name) return (this->*make)(sweep, process, dt, depth);
  throw Error(ExitCode::internal,
              fmt::format("sweep '{}' is generic but kernels/cpu/sweeps.cpp does not list its "
                          "cell function",
                          sweep.name));
}

template <class Real>
void CpuBackend<Real>::run_generic(const SweepInfo& sweep, Process process, Real dt,
                                   StepTally& tally) {
  const GenericRows rows = generic_rows(sweep, process, dt);
  for_rows(1, H_ - 1, [&](int y) { rows.row(y); });
  rows.book(tally);
}

template void CpuBackend<float>::run_generic(const SweepInfo&, Process, float, StepTally&);
template void CpuBackend<double>::run_generic(const SweepInfo&, Process, double, StepTally&);
template CpuBackend<float>::GenericRows CpuBackend<float>::generic_rows(const SweepInfo&, Process,
                                                                        float, float*);
template CpuBackend<double>::GenericRows CpuBackend<double>::generic_rows(const SweepInfo&, Process,
                                                                          double, double*);

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
