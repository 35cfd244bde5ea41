#include "cpu/cpu_backend.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "common/sections.h"
#include "common/stats.h"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/initial_state.hpp"
#include "stats_merge.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
CpuBackend<Real>::CpuBackend(const Terrain& terrain, const Params& params)
    : params_(params),
      cell_(cell_params_of<Real>(params)),
      nx_(terrain.grid.nx),
      ny_(terrain.grid.ny),
      W_(terrain.grid.nx + 2),
      H_(terrain.grid.ny + 2) {
  PaddedState s = build_padded_state(terrain, params);
  periodic_ = s.periodic_x;
  stats_in_pass_ = step_sequence(params).back() == Process::evaporation;
  cell_.flow.periodic_x = periodic_ ? 1 : 0;
#ifdef _OPENMP
  threads_ = params.numerics.threads > 0 ? params.numerics.threads : omp_get_max_threads();
#else
  threads_ = 1;
#endif
  // The padded state's float64 arrays, rounded to Real, into a per-row array or a field, each
  // freed once taken, and the fields that start at zero made after the last: the setup then
  // peaks at the state's own size (a 2048^2 run with erosion peaked 146 B/cell above its
  // start while it built, 107 once built; performance.md "Resident memory per cell").
  auto take = [](auto& dst, std::vector<double>& v) {
    dst.assign(v.begin(), v.end());
    std::vector<double>().swap(v);
  };
  const std::size_t n = s.size();
  kind_ = std::move(s.kind);
  take(dx_, s.dx);
  take(dy_, s.dy);
  take(area_, s.area);
  take(bed_, s.bed);
  bed_next_ = bed_;
  bed0_ = bed_;
  take(depth_, s.depth);
  depth_next_ = depth_;
  wetness_ = depth_;
  take(sediment_, s.sediment);
  sediment_next_ = sediment_;
  take(manning_, s.manning);
  take(hardness_, s.hardness);
  take(rain_factor_, s.rain_factor);
  bed_residual_.assign(n, Real(0));
  for (int k = 0; k < 4; ++k) {
    flux_[k].assign(n, Real(0));
    flux_next_[k].assign(n, Real(0));
  }
  velocity_x_.assign(n, Real(0));
  velocity_y_.assign(n, Real(0));
  thermal_share_.assign(n, Real(0));
  row_sums_a_.assign(H_, 0.0);
  row_sums_b_.assign(H_, 0.0);
  row_sums_c_.assign(H_, 0.0);
  const std::size_t cells = n;
  fields_.bind(*this, [cells] { return Field(cells, Real(0)); });
  run_boundary();
  exchange_halo({"bed", "water_depth", "sediment"});  // the corners after the ghost rows
}

template <class Real>
std::string CpuBackend<Real>::device() const {
  return fmt::format("CPU reference, {}, {} thread{}, {}",
                     sizeof(Real) == 4 ? "float32" : "float64", threads_, threads_ == 1 ? "" : "s",
                     cpu_isa_label);
}

template <class Real>
double CpuBackend<Real>::sum_rows(const std::vector<double>& rows) {
  double s = 0.0;
  for (double v : rows) s += v;
  return s;
}

template <class Real>
void CpuBackend<Real>::begin_step(const StepInputs& in) {
  step_inputs_ = in;
  step_cell_params(cell_, in);
  step_tally_ = StepTally{};
  pass_stats_ = false;
  face_water_.assign(face_codes_.size(), 0.0);
  face_sediment_.assign(face_codes_.size(), 0.0);
  in_step_ = true;
  cell_.boundary.sea_level = static_cast<Real>(step_level(in, params_));
}

template <class Real>
void CpuBackend<Real>::run(Process p) {
  if (!in_step_) throw Error(ExitCode::internal, "backend: run() outside a step (begin_step)");
  pass_stats_ = false;  // the state changes after the fused pass's statistics
  const StepInputs& in = step_inputs_;
  StepTally& tally = step_tally_;
  const Real dt = static_cast<Real>(in.dt);
  switch (p) {
    case Process::boundary:
      run_boundary();
      break;
    case Process::sources:
      run_sources(in);
      break;
    case Process::flow:
      run_flow(dt);
      break;
    case Process::water:
      measure_water_faces();
      run_water(dt, tally);
      break;
    case Process::erosion:
      run_erosion(dt, tally);
      break;
    case Process::transport:
      measure_sediment_faces();
      run_transport(dt, tally);
      break;
    case Process::thermal:
      run_thermal(dt, tally);
      break;
    default:  // the processes whose sweeps are all generic
      break;
  }
  // the generic sweeps of the process (SweepInfo::generic), after its own loops, and the halo
  // exchange after every sweep (run_thermal and run_flow exchange between their own passes)
  run_sweeps_tail(
      process_info(p).sweeps(params_), periodic_,
      [&](const SweepInfo& s) { run_generic(s, p, dt, tally); },
      [&](const std::vector<std::string>& names) { exchange_halo(names); });
}

template <class Real>
bool CpuBackend<Real>::fuses(const std::vector<Process>& pass) const {
  // fused_passes() leaves out shallow water and generic sweeps; a periodic halo is exchanged
  // between the three, so it runs them one by one
  const std::vector<Process> flow_water{Process::flow, Process::sources, Process::water},
      water_only{Process::flow, Process::sources, Process::water, Process::evaporation};
  return (pass == flow_water || pass == water_only) &&
         params_.flow.scheme != FlowScheme::shallow_water && !periodic_;
}

template <class Real>
void CpuBackend<Real>::run_pass(const std::vector<Process>& pass) {
  if (!fuses(pass)) {
    Backend::run_pass(pass);
    return;
  }
  if (!in_step_) throw Error(ExitCode::internal, "backend: run_pass() outside a step (begin_step)");
  pass_stats_ = false;
  run_flow_water(static_cast<Real>(step_inputs_.dt), step_tally_,
                 pass.back() == Process::evaporation);
}

template <class Real>
void CpuBackend<Real>::exchange_halo(const std::vector<std::string>& names) {
  if (!periodic_) return;
  for (const std::string& name : names) {
    Field* f = name == "depth_flow"      ? &depth_next_
               : name == "thermal_share" ? &thermal_share_
                                         : field_storage(field_info(name).id);
    if (!f)
      throw Error(ExitCode::internal,
                  fmt::format("halo exchange: field '{}' has no storage", name));
    copy_periodic_columns(f->data(), W_, H_);
  }
}

template <class Real>
StepResult CpuBackend<Real>::end_step() {
  if (!in_step_) throw Error(ExitCode::internal, "backend: end_step() outside a step");
  in_step_ = false;
  StepResult r;
  r.tally = step_tally_;
  // the statistics the fused pass took of each row as it left it, when it ran last
  r.stats = pass_stats_ ? merge_row_stats(pass_stats_rows_) : stats();
  pass_stats_ = false;
  // The probes straight from the fields (host memory): no copy of a whole field.
  r.probes.reserve(probe_fields_.size() * probe_cells_.size());
  for (const FieldId id : probe_fields_) {
    const Field* src = fields_.peek(id);  // a field not made yet reads as zeros
    for (const std::size_t p : probe_cells_) r.probes.push_back(value_at(id, src, p));
  }
  r.face_water = face_water_;
  r.face_sediment = face_sediment_;
  return r;
}

template <class Real>
void CpuBackend<Real>::set_faces(const std::vector<Face>& faces) {
  face_codes_ = padded_faces(faces, nx_, ny_);
  face_water_.assign(face_codes_.size(), 0.0);
  face_sediment_.assign(face_codes_.size(), 0.0);
}

template <class Real>
void CpuBackend<Real>::measure_water_faces() {
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  for (std::size_t j = 0; j < face_codes_.size(); ++j)
    face_water_[j] = cell::section_face_water(face_codes_[j], W_, fl, fr, ft, fb);
}

template <class Real>
void CpuBackend<Real>::measure_sediment_faces() {
  // before the transport: the sediment it starts from, the depth the flow step limited the
  // outflows by (depth_next_ after the water update's swap) and the outflows
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  for (std::size_t j = 0; j < face_codes_.size(); ++j)
    face_sediment_[j] = cell::section_face_sediment(face_codes_[j], W_, sediment_.data(),
                                                    depth_next_.data(), fl, fr, ft, fb);
}

template <class Real>
void CpuBackend<Real>::set_probes(const std::vector<std::int64_t>& cells,
                                  const std::vector<FieldId>& fields) {
  check_cells(cells, nx_, ny_, "probes");
  probe_cells_.clear();
  for (const std::int64_t cell : cells) probe_cells_.push_back(padded(cell));
  probe_fields_ = fields;
}

template <class Real>
std::vector<double> CpuBackend<Real>::sample(const std::vector<std::int64_t>& cells,
                                             FieldId id) const {
  check_cells(cells, nx_, ny_, "sample");
  const Field* src = fields_.peek(id);  // a field not made yet reads as zeros
  std::vector<double> out;
  out.reserve(cells.size());
  for (const std::int64_t cell : cells) out.push_back(value_at(id, src, padded(cell)));
  return out;
}

template <class Real>
FieldStats CpuBackend<Real>::stats() {
  std::vector<RowStats> rows(static_cast<std::size_t>(H_ - 2));
  for_rows(1, H_ - 1,
           [&](int y) { rows[static_cast<std::size_t>(y - 1)] = stats_row(y, depth_.data()); });
  return merge_row_stats(rows);
}

template <class Real>
RowStats CpuBackend<Real>::stats_row(int y, const Real* depth) const {
  RowStats row;
  const Kind* kind = kind_.data();
  const Real *bed = bed_.data(), *bed_lo = bed_residual_.data(), *sediment = sediment_.data(),
             *vx = velocity_x_.data(), *vy = velocity_y_.data();
  const double a = area_[y];
  const std::size_t base = static_cast<std::size_t>(y) * W_;
  const std::int64_t row_cell = static_cast<std::int64_t>(y - 1) * nx_ - 1;
  double water = 0, material = 0, sed = 0, max_d = -1, max_v2 = -1;
  std::size_t fastest = 0;
  for (int x = 1; x < W_ - 1; ++x) {
    const std::size_t i = base + static_cast<std::size_t>(x);
    if (kind[i] != ERODEM_CELL_ACTIVE) continue;
    const Real d = depth[i], b = bed[i], s = sediment[i];
    if (row.bad_cell < 0 && !cell::cell_state_ok(b, d, s)) row.bad_cell = row_cell + x;
    water += static_cast<double>(d) * a;
    material +=
        (static_cast<double>(b) + static_cast<double>(bed_lo[i]) + static_cast<double>(s)) * a;
    sed += static_cast<double>(s) * a;
    if (d > max_d) {
      max_d = d;
      row.max_depth_cell = row_cell + x;
    }
    // The squared speed ranks the cells (products of floats are exact in double), as in
    // stats.cl; the winner's speed is hypot below.
    const double u = vx[i], v = vy[i];
    const double v2 = u * u + v * v;
    if (v2 > max_v2) {
      max_v2 = v2;
      row.max_speed_cell = row_cell + x;
      fastest = i;
    }
  }
  row.water = water;
  row.material = material;
  row.sediment = sed;
  row.max_depth = max_d;
  row.max_speed2 = max_v2;
  if (row.max_speed_cell >= 0)
    row.speed = std::hypot(static_cast<double>(vx[fastest]), static_cast<double>(vy[fastest]));
  return row;
}

template <class Real>
std::vector<double> CpuBackend<Real>::field(FieldId id) const {
  std::vector<double> out(static_cast<std::size_t>(nx_) * ny_);
  const Field* src = fields_.peek(id);  // a field not made yet reads as zeros
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c)
      out[static_cast<std::size_t>(r) * nx_ + c] = value_at(id, src, at(c + 1, r + 1));
  return out;
}

template <class Real>
void CpuBackend<Real>::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  if (fields_.setting_keeps_unmade(id, values)) return;  // reads give these zeros already
  Field* dst = field_storage(id);
  if (!dst)
    throw Error(ExitCode::usage,
                fmt::format("field '{}' is derived and cannot be set", field_info(id).name));
  // Fields kept in two buffers get both, so the next step starts from the new values.
  Field* twin = fields_.twin(id);
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c) {
      const auto p = at(c + 1, r + 1);
      const double value = values[static_cast<std::size_t>(r) * nx_ + c];
      const auto v = static_cast<Real>(value);
      (*dst)[p] = v;
      if (twin) (*twin)[p] = v;
      // a bed keeps what Real cannot hold in its residual (set bed_residual after the bed)
      if (id == FieldId::bed) bed_residual_[p] = static_cast<Real>(value - static_cast<double>(v));
    }
  if (periodic_) {
    copy_periodic_columns(dst->data(), W_, H_);
    if (twin) copy_periodic_columns(twin->data(), W_, H_);
    if (id == FieldId::bed) copy_periodic_columns(bed_residual_.data(), W_, H_);
  }
}

template <class Real>
HostView CpuBackend<Real>::host_view(FieldId id) {
  Field* src = field_storage(id);
  if (!src) return {};
  return {src->data() + at(1, 1), sizeof(Real), static_cast<std::ptrdiff_t>(W_)};
}

template class CpuBackend<float>;
template class CpuBackend<double>;

#if defined(ERODEM_CPU_NATIVE)
const char* const cpu_isa_label = "native";
#elif ERODEM_CPU_ISA_LEVEL == 4
const char* const cpu_isa_label = "AVX-512";
#elif ERODEM_CPU_ISA_LEVEL == 3
const char* const cpu_isa_label = "AVX2";
#else
const char* const cpu_isa_label = "SSE4.2";
#endif

std::unique_ptr<Backend> make_cpu_backend_isa(const Terrain& terrain, const Params& params) {
  if (params.numerics.precision == Precision::float64)
    return std::make_unique<CpuBackend<double>>(terrain, params);
  return std::make_unique<CpuBackend<float>>(terrain, params);
}

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
