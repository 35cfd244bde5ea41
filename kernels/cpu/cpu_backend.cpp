#include "cpu/cpu_backend.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "band_rows.hpp"
#include "common/sections.h"
#include "common/stats.h"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/initial_state.hpp"
#include "erodem/parallel.hpp"
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
  // the padded rows this backend holds: all of them, or a band's (band_rows.hpp)
  band_ = band_rows(params, ny_);
  H_ = band_.rows;
  PaddedState s = build_padded_state(terrain, params, band_.row0, band_.row0 + H_);
  periodic_ = s.periodic_x;
  tails_ = sweeps_tails(params, periodic_ || band_.banded, band_.banded ? band_.halo : 0);
  stats_in_pass_ = step_sequence(params).back() == Process::evaporation;
  changes_material_ = material_changers(params);
  material_rows_.resize(static_cast<std::size_t>(H_ - 2));
  cell_.flow.periodic_x = periodic_ ? 1 : 0;
#ifdef _OPENMP
  threads_ = params.numerics.threads > 0 ? params.numerics.threads : omp_get_max_threads();
  // the processes a launcher started on this machine (the ranks of an MPI run, an ensemble's
  // members) share its cores, unless numerics.threads or OMP_NUM_THREADS says otherwise
  if (parallel::local_size() > 1 && params.numerics.threads <= 0 && !std::getenv("OMP_NUM_THREADS"))
    threads_ = std::max(1, threads_ / parallel::local_size());
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
  bed0_ = bed_;
  take(depth_, s.depth);
  depth_next_ = depth_;
  wetness_ = depth_;
  take(sediment_, s.sediment);
  // (any run with the semi-Lagrangian scheme, so that the transport can run without erosion
  // too, as the tests' run_processes does)
  if (params.transport.scheme == TransportScheme::semi_lagrangian) sediment_next_ = sediment_;
  // the parameters the terrain classes write are held per cell from the start
  take_parameter(manning_, s.manning, cell_.terrain_class.set_manning != 0);
  take_parameter(hardness_, s.hardness, cell_.terrain_class.set_hardness != 0);
  take_parameter(rain_factor_, s.rain_factor, false);
  update_param_pitches();
  // The fields that start at zero: value-initialised, so their pages are taken when a step
  // first writes them, after the terrain's own arrays are freed (stagger.hpp).
  bed_residual_ = Field(n);
  for (int k = 0; k < 4; ++k) flux_[k] = Field(n);  // every scheme writes them in place
  velocity_x_ = Field(n);
  velocity_y_ = Field(n);
  thermal_share_ = Field(n);
  row_sums_a_.assign(H_, 0.0);
  row_sums_b_.assign(H_, 0.0);
  row_sums_c_.assign(H_, 0.0);
  edge_row_.assign(static_cast<std::size_t>(H_) + 1, 0);
  for (int y = 1; y < H_ - 1; ++y) {
    for (int x = 1; x < W_ - 1; ++x)
      if (cell::active_beside_inactive(x + y * W_, W_, kind_.data())) edge_x_.push_back(x);
    edge_row_[static_cast<std::size_t>(y) + 1] = static_cast<int>(edge_x_.size());
  }
  edge_row_[static_cast<std::size_t>(H_)] = static_cast<int>(edge_x_.size());
  // ERODEM_CPU_ACTIVE_ROWS=0: no row counts as all active, so every loop reads the kinds (the
  // same bits: ActiveRows in tests/test_fused.cpp compares the two)
  const char* active_rows = std::getenv("ERODEM_CPU_ACTIVE_ROWS");
  const bool constant_kinds = !(active_rows && std::string(active_rows) == "0");
  row_active_.assign(static_cast<std::size_t>(H_), 0);
  for (int y = 0; y < H_ && constant_kinds; ++y) {
    const Kind* k = kind_.data() + static_cast<std::size_t>(y) * W_;
    row_active_[static_cast<std::size_t>(y)] =
        std::all_of(k + 1, k + W_ - 1, [](Kind c) { return c == ERODEM_CELL_ACTIVE; });
  }
  const std::size_t cells = n;
  fields_.bind(*this, [cells] { return Field(cells); });
  run_boundary();
  exchange_halo({"bed", "water_depth", "sediment"});  // the corners after the ghost rows
}

template <class Real>
void CpuBackend<Real>::take_parameter(Field& dst, CellParameter& src, bool per_cell) {
  if (!src.is_uniform()) {
    dst.assign(src.cells.begin(), src.cells.end());
    std::vector<double>().swap(src.cells);
    return;
  }
  dst.assign(static_cast<std::size_t>(W_), static_cast<Real>(src.uniform));
  if (per_cell) make_per_cell(dst);
}

template <class Real>
void CpuBackend<Real>::make_per_cell(Field& f) {
  if (!uniform(f)) return;
  Field all(static_cast<std::size_t>(W_) * static_cast<std::size_t>(H_));
  for (int y = 0; y < H_; ++y) std::copy(f.begin(), f.end(), all.begin() + at(0, y));
  f.swap(all);
  update_param_pitches();
}

template <class Real>
std::string CpuBackend<Real>::device() const {
  return fmt::format(
      "CPU reference, {}, {} thread{}, {}{}", sizeof(Real) == 4 ? "float32" : "float64", threads_,
      threads_ == 1 ? "" : "s", cpu_isa_label,
      band_.banded ? fmt::format(" (a rank), {} MPI ranks in bands of rows, halo {} row{}",
                                 parallel::size(), band_.halo, band_.halo == 1 ? "" : "s")
                   : "");
}

template <class Real>
double CpuBackend<Real>::sum_rows(const std::vector<double>& rows) const {
  // In a band: the sums of every rank's own rows in global row order. The grid's ghost rows
  // (0 in every row sum) and the halo rows are left out; adding 0.0 to a sum that starts at
  // +0.0 changes no bit, so this is the one-process sum.
  const std::vector<double> all = band_.banded
                                      ? parallel::allgather(std::vector<double>(
                                            rows.begin() + band_.own0, rows.begin() + band_.own1))
                                      : std::vector<double>();
  double s = 0.0;
  for (double v : band_.banded ? all : rows) s += v;
  return s;
}

template <class Real>
template <class F>
std::vector<double> CpuBackend<Real>::gather_cells(const std::vector<std::int64_t>& cells,
                                                   const F& value) const {
  std::vector<double> mine;
  for (const std::int64_t cell : cells)
    if (owns(cell)) mine.push_back(value(padded(cell)));
  if (!band_.banded) return mine;
  return parallel::gather_owned(cell_owners(cells, nx_, ny_), mine);
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
  if (changes_material_.at(static_cast<std::size_t>(p))) material_known_ = false;
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
      tails_.at(static_cast<std::size_t>(p)),
      [&](const SweepInfo& s) { run_generic(s, p, dt, tally); },
      [&](const std::vector<std::string>& names, const std::vector<std::string>& unsent) {
        exchange_halo(names, unsent);
      });
}

template <class Real>
std::vector<std::vector<Process>> CpuBackend<Real>::fused_parts(
    const std::vector<Process>& pass) const {
  // fused_passes() leaves out shallow water and generic sweeps; a periodic halo, or the halo
  // rows of an MPI band, are exchanged between the three, so it runs them one by one. The
  // pass of flow, sources, water (and evaporation after them, or erosion: that one alone).
  const std::vector<Process> flow_water{Process::flow, Process::sources, Process::water};
  if (params_.flow.scheme == FlowScheme::shallow_water || periodic_ || band_.banded ||
      pass.size() < flow_water.size() ||
      !std::equal(flow_water.begin(), flow_water.end(), pass.begin()))
    return Backend::fused_parts(pass);
  const std::size_t n = pass.size() > 3 && pass[3] == Process::evaporation ? 4 : 3;
  std::vector<std::vector<Process>> parts{
      {pass.begin(), pass.begin() + static_cast<std::ptrdiff_t>(n)}};
  for (std::size_t k = n; k < pass.size(); ++k) parts.push_back({pass[k]});
  return parts;
}

template <class Real>
void CpuBackend<Real>::run_fused(const std::vector<Process>& part) {
  if (!in_step_) throw Error(ExitCode::internal, "backend: run_pass() outside a step (begin_step)");
  if (part.size() < 3 || part[0] != Process::flow || part[2] != Process::water)
    throw Error(ExitCode::internal, "backend: no fused pass for this part of a pass");
  pass_stats_ = false;
  for (const Process p : part)
    if (changes_material_.at(static_cast<std::size_t>(p))) material_known_ = false;
  run_flow_water(static_cast<Real>(step_inputs_.dt), step_tally_,
                 part.back() == Process::evaporation);
}

template <class Real>
void CpuBackend<Real>::exchange_halo(const std::vector<std::string>& names,
                                     const std::vector<std::string>& unsent) {
  if (!periodic_ && !band_.banded) return;
  std::vector<Real*> fields, sent;
  for (const std::string& name : names) {
    Field* f = name == "depth_flow"      ? &depth_next_
               : name == "thermal_share" ? &thermal_share_
                                         : fields_.get(field_info(name).id);
    if (!f)
      throw Error(ExitCode::internal,
                  fmt::format("halo exchange: field '{}' has no storage", name));
    if (uniform(*f)) continue;  // a uniform parameter: every row holds its one row
    fields.push_back(f->data());
    if (std::find(unsent.begin(), unsent.end(), name) == unsent.end()) sent.push_back(f->data());
  }
  exchange_fields(fields, sent);
}

template <class Real>
void CpuBackend<Real>::exchange_fields(const std::vector<Real*>& copied,
                                       const std::vector<Real*>& fields) {
  if (periodic_)
    for (Real* f : copied) copy_periodic_columns(f, W_, H_);
  if (!band_.banded || fields.empty()) return;
  // whole padded rows (the ghost columns and the corners with them): my first band_.halo own
  // rows to the band above, my last to the band below; theirs into my halo rows. Every field's
  // rows packed into one message each way.
  const int r = parallel::rank(), ranks = parallel::size();
  const bool up = r > 0, down = r + 1 < ranks;
  const std::size_t per = static_cast<std::size_t>(band_.halo) * static_cast<std::size_t>(W_);
  const std::size_t n = per * fields.size();
  halo_buffer_.resize(4 * n);
  Real *send_up = halo_buffer_.data(), *recv_up = send_up + n, *send_down = recv_up + n,
       *recv_down = send_down + n;
  auto row = [&](Real* f, int y) { return f + static_cast<std::size_t>(y) * W_; };
  for (std::size_t k = 0; k < fields.size(); ++k) {
    std::copy_n(row(fields[k], band_.own0), per, send_up + k * per);
    std::copy_n(row(fields[k], band_.own1 - band_.halo), per, send_down + k * per);
  }
  parallel::exchange(up ? send_up : nullptr, up ? recv_up : nullptr, down ? send_down : nullptr,
                     down ? recv_down : nullptr, n * sizeof(Real));
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (up) std::copy_n(recv_up + k * per, per, row(fields[k], band_.own0 - band_.halo));
    if (down) std::copy_n(recv_down + k * per, per, row(fields[k], band_.own1));
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
    for (const double v :
         gather_cells(probe_cells_, [&](std::size_t p) { return value_at(id, src, p); }))
      r.probes.push_back(v);
  }
  r.face_water = gather_faces(face_water_);
  r.face_sediment = gather_faces(face_sediment_);
  return r;
}

template <class Real>
void CpuBackend<Real>::set_faces(const std::vector<Face>& faces) {
  face_codes_ = padded_faces(faces, nx_, ny_);
  // MPI: the faces this band owns (face_owners: their far cells are in the band or its
  // halo); others' -1
  face_owner_ = face_owners(faces, ny_);
  const int rank = parallel::rank();
  if (band_.banded)
    for (std::size_t j = 0; j < faces.size(); ++j)
      face_codes_[j] = face_owner_[j] == rank ? band_.face_code(face_codes_[j], nx_) : -1;
  face_water_.assign(face_codes_.size(), 0.0);
  face_sediment_.assign(face_codes_.size(), 0.0);
}

template <class Real>
std::vector<double> CpuBackend<Real>::gather_faces(const std::vector<double>& values) const {
  if (!band_.banded) return values;
  std::vector<double> mine;
  for (std::size_t j = 0; j < values.size(); ++j)
    if (face_codes_[j] >= 0) mine.push_back(values[j]);
  return parallel::gather_owned(face_owner_, mine);
}

template <class Real>
void CpuBackend<Real>::measure_water_faces() {
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  for (std::size_t j = 0; j < face_codes_.size(); ++j)
    if (face_codes_[j] >= 0)
      face_water_[j] = cell::section_face_water(face_codes_[j], W_, fl, fr, ft, fb);
}

template <class Real>
void CpuBackend<Real>::measure_sediment_faces() {
  // before the transport: the sediment it starts from, the depth the flow step limited the
  // outflows by (depth_next_ after the water update's swap) and the outflows
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  for (std::size_t j = 0; j < face_codes_.size(); ++j)
    if (face_codes_[j] >= 0)
      face_sediment_[j] = cell::section_face_sediment(face_codes_[j], W_, sediment_.data(),
                                                      depth_next_.data(), fl, fr, ft, fb);
}

template <class Real>
void CpuBackend<Real>::set_probes(const std::vector<std::int64_t>& cells,
                                  const std::vector<FieldId>& fields) {
  check_cells(cells, nx_, ny_, "probes");
  probe_cells_ = cells;
  probe_fields_ = fields;
}

template <class Real>
std::vector<double> CpuBackend<Real>::sample(const std::vector<std::int64_t>& cells,
                                             FieldId id) const {
  check_cells(cells, nx_, ny_, "sample");
  const Field* src = fields_.peek(id);  // a field not made yet reads as zeros
  return gather_cells(cells, [&](std::size_t p) { return value_at(id, src, p); });
}

template <class Real>
FieldStats CpuBackend<Real>::stats() {
  std::vector<RowStats> rows(static_cast<std::size_t>(H_ - 2));
  const bool known = material_known();
  for_rows(1, H_ - 1, [&](int y) {
    rows[static_cast<std::size_t>(y - 1)] = stats_row(y, depth_.data(), known);
  });
  material_known_ = true;
  if (band_.banded)  // every rank's own rows, in global row order
    rows = parallel::allgather(
        std::vector<RowStats>(rows.begin() + (band_.own0 - 1), rows.begin() + (band_.own1 - 1)));
  return merge_row_stats(rows);
}

namespace {
// Four lanes of doubles and their masks, GCC's vector extensions: the operations are IEEE's,
// element by element, whatever registers a build has (an SSE build splits each vector in two),
// so every build adds the same values in the same order. 32 bytes, not 64: without AVX-512,
// GCC lowered the 64-byte vectors' selects to a test and a branch per element and kept the
// sums on the stack (a third of the statistics' time, AVX2).
typedef double Double4 __attribute__((vector_size(32)));
typedef long long Mask4 __attribute__((vector_size(32)));
typedef std::uint8_t Byte4 __attribute__((vector_size(4)));

// (results through references: a 32-byte vector returned by value changes the ABI between the
// v2 build and the others, GCC's -Wpsabi)
/// Eight values as two vectors of doubles. (__builtin_convertvector converted two floats at a
/// time and moved the upper two through the stack; GCC's loop vectoriser converts four.)
inline void load8(const float* p, Double4& lo, Double4& hi) {
  double t[8];
  for (int j = 0; j < 8; ++j) t[j] = p[j];
  std::memcpy(&lo, t, sizeof lo);
  std::memcpy(&hi, t + 4, sizeof hi);
}
inline void load8(const double* p, Double4& lo, Double4& hi) {
  std::memcpy(&lo, p, sizeof lo);
  std::memcpy(&hi, p + 4, sizeof hi);
}
/// All ones where the kind is ERODEM_CELL_ACTIVE, else 0.
inline void active4(const std::uint8_t* kind, Mask4& mask) {
  Byte4 k;
  std::memcpy(&k, kind, sizeof k);
  mask = __builtin_convertvector(k == Byte4{} + ERODEM_CELL_ACTIVE, Mask4);
}
/// sum += v where mask is all ones, += +0 where it is 0 (the bits of v and-ed with the mask).
inline void add_where(Double4& sum, const Mask4& mask, const Double4& v) {
  Mask4 bits;
  std::memcpy(&bits, &v, sizeof bits);
  bits &= mask;
  Double4 masked;
  std::memcpy(&masked, &bits, sizeof masked);
  sum += masked;
}

/// The largest of four lanes (none NaN).
inline double lane_max(const Double4& v) {
  const double a = v[0] > v[1] ? v[0] : v[1], b = v[2] > v[3] ? v[2] : v[3];
  return a > b ? a : b;
}
/// The smallest of four lanes (none NaN).
inline double lane_min(const Double4& v) {
  const double a = v[0] < v[1] ? v[0] : v[1], b = v[2] < v[3] ? v[2] : v[3];
  return a < b ? a : b;
}

/// What stats_row's one pass over a row finds besides the volumes: the largest depth and the
/// largest squared speed of the row's active cells (-1 where none beats -1; NaN never ranks) and
/// the first chunk of `chunk` cells holding each, and the smallest depth (+inf where none).
struct RowExtremes {
  double max_depth = -1, max_speed2 = -1, min_depth = std::numeric_limits<double>::infinity();
  int depth_chunk = 0, speed_chunk = 0;
};

/// One pass over the n cells of arrays that start at a row's first DEM cell, for stats_row:
///  - the volumes: cell x into lane x % 16 of pw (depth) and, with kMaterial, of pm (bed +
///    residual + sediment) and ps (sediment), each in x order (an inactive cell adds +0): the
///    cells [0, n - n % 16) four vectors of four lanes at a time, the rest one by one into
///    lanes 0, 1, ...;
///  - per chunk of `chunk` cells (a multiple of 16), the largest and smallest depth and the
///    largest squared speed u*u + v*v in double (exact for floats), each chunk's maximum ranked
///    against the earlier chunks' strictly, so that each kept chunk is the first holding the
///    row's largest value. Maxima and minima do not depend on the order of the lanes, which
///    compare the depths in double: exact for a float depth, as the float comparison.
/// The lanes stay in registers: without AVX-512, GCC lowered a select on 64-byte vectors to a
/// test and a branch per element, and kept a simd reduction's mixed float and double maxima
/// on the stack with byte masks repacked per vector (performance.md "The statistics in one
/// pass").
template <bool kMaterial, class Real>
void row_pass(const std::uint8_t* kind, const Real* d, const Real* bed, const Real* bed_lo,
              const Real* sediment, const Real* vx, const Real* vy, int n, int chunk, double* pw,
              double* pm, double* ps, RowExtremes& e) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Double4 minus_one = Double4{} - 1.0, infinity = Double4{} + inf;
  const int whole = n - n % 16;
  Double4 w[4] = {}, m[4] = {}, s[4] = {};
  for (int c0 = 0; c0 < n; c0 += chunk) {
    const int c1 = std::min(c0 + chunk, n), v1 = std::min(c1, whole);
    Double4 hi = minus_one, fast = minus_one, lo = infinity;
    for (int x0 = c0; x0 < v1; x0 += 16)
      for (int half = 0; half < 2; ++half) {
        const int x8 = x0 + 8 * half;
        Double4 h8[2], u8[2], v8[2], b8[2], l8[2], s8[2];
        load8(d + x8, h8[0], h8[1]);
        load8(vx + x8, u8[0], u8[1]);
        load8(vy + x8, v8[0], v8[1]);
        if constexpr (kMaterial) {
          load8(bed + x8, b8[0], b8[1]);
          load8(bed_lo + x8, l8[0], l8[1]);
          load8(sediment + x8, s8[0], s8[1]);
        }
        for (int k = 0; k < 2; ++k) {
          const int q = 2 * half + k;
          const Double4 h = h8[k], u = u8[k], v = v8[k];
          Mask4 active;
          active4(kind + x8 + 4 * k, active);
          add_where(w[q], active, h);
          if constexpr (kMaterial) {
            add_where(m[q], active, b8[k] + l8[k] + s8[k]);
            add_where(s[q], active, s8[k]);
          }
          const Double4 h_rank = active & (h > minus_one) ? h : minus_one;  // NaN: -1
          hi = h_rank > hi ? h_rank : hi;
          const Double4 h_low = active ? h : infinity;
          lo = h_low < lo ? h_low : lo;
          const Double4 v2 = u * u + v * v;
          const Double4 v2_rank = active & (v2 > minus_one) ? v2 : minus_one;
          fast = v2_rank > fast ? v2_rank : fast;
        }
      }
    double c_hi = lane_max(hi), c_fast = lane_max(fast), c_lo = lane_min(lo);
    if (c1 == n) {  // the last chunk: every vector add is done, the tail adds after them
      std::memcpy(pw, w, sizeof w);
      if constexpr (kMaterial) {
        std::memcpy(pm, m, sizeof m);
        std::memcpy(ps, s, sizeof s);
      }
    }
    for (int x = std::max(c0, whole); x < c1; ++x) {  // the tail, into lanes 0 .. n - whole - 1
      const std::size_t j = static_cast<std::size_t>(x - whole);
      const bool active = kind[x] == ERODEM_CELL_ACTIVE;
      const double h = d[x];
      pw[j] += active ? h : 0.0;
      if constexpr (kMaterial) {
        const double sv = sediment[x];
        pm[j] += active ? static_cast<double>(bed[x]) + static_cast<double>(bed_lo[x]) + sv : 0.0;
        ps[j] += active ? sv : 0.0;
      }
      const double h_rank = active && h > -1 ? h : -1.0;
      c_hi = h_rank > c_hi ? h_rank : c_hi;
      const double h_low = active ? h : inf;
      c_lo = h_low < c_lo ? h_low : c_lo;
      const double u = vx[x], v = vy[x], v2 = u * u + v * v;
      const double v2_rank = active && v2 > -1 ? v2 : -1.0;
      c_fast = v2_rank > c_fast ? v2_rank : c_fast;
    }
    if (c_hi > e.max_depth) e.max_depth = c_hi, e.depth_chunk = c0;
    if (c_fast > e.max_speed2) e.max_speed2 = c_fast, e.speed_chunk = c0;
    e.min_depth = c_lo < e.min_depth ? c_lo : e.min_depth;
  }
}
}  // namespace

template <class Real>
RowStats CpuBackend<Real>::stats_row(int y, const Real* depth, bool material_known) {
  // The row's volumes (in the fixed order of sum_row's lanes) and the results of one scan of
  // its active cells in x order (the first cell of the largest depth and of the largest
  // squared speed, "larger" strictly, so NaN never wins; the first cell not physical)
  // (performance.md "The statistics' row passes", "Sums in sixteen lanes", "The statistics in
  // one pass"):
  //  1. one pass over the row (row_pass): the three volumes in the lanes of sum_row (an
  //     inactive cell adds +0, which leaves a sum as it is: a sum that starts at +0 never
  //     becomes -0), times the area; and per chunk of kStatsChunk cells, the largest depth and
  //     squared speed and the smallest depth (in vector lanes: a maximum's value does not
  //     depend on the order), the chunks ranked as the scan ranks cells (strictly larger), so
  //     the first chunk holding each largest value is the scan's;
  //  2. the first cell in that chunk holding that value;
  //  3. only where a volume is not finite or a depth negative, the scan for the first cell
  //     that is not physical (a NaN or infinite depth, bed or sediment makes a volume so).
  RowStats row;
  const std::size_t base = static_cast<std::size_t>(y) * W_;
  const Kind* __restrict kind = kind_.data() + base;
  const Real* __restrict d = depth + base;
  const Real* __restrict bed = bed_.data() + base;
  const Real* __restrict bed_lo = bed_residual_.data() + base;
  const Real* __restrict sediment = sediment_.data() + base;
  const Real* __restrict vx = velocity_x_.data() + base;
  const Real* __restrict vy = velocity_y_.data() + base;
  const double a = area_[y];
  const int W = W_;
  const std::int64_t row_cell = static_cast<std::int64_t>(y - 1 + band_.row0) * nx_ - 1;
  // The squared speed ranks the cells (products of floats are exact in double), as in
  // stats.cl; the winner's speed is hypot below. The search computes it as row_pass's lanes
  // and tail do (u * u + v * v in double, never contracted: -ffp-contract=off), so it finds the
  // cell by equality with row_pass's value.
  auto speed2 = [vx, vy](int x) {
    const double u = vx[x], v = vy[x];
    return u * u + v * v;
  };

  // the volumes: each a sum over the row's cells in the lanes of sum_row (cell x's value into
  // lane (x - 1) % kSumLanes, +0 for an inactive cell), combined by sum_lanes, times the
  // cells' area; the material's and the sediment's only when they may have changed
  // (material_rows_); and the extremes, in the same pass (row_pass)
  static_assert(kSumLanes == 16, "row_pass holds sixteen lanes");
  static_assert(kStatsChunk % 16 == 0, "row_pass's chunks hold whole vectors of lanes");
  double pw[kSumLanes] = {}, pm[kSumLanes] = {}, ps[kSumLanes] = {};
  RowExtremes e;
  if (material_known)
    row_pass<false>(kind + 1, d + 1, bed + 1, bed_lo + 1, sediment + 1, vx + 1, vy + 1, W - 2,
                    kStatsChunk, pw, pm, ps, e);
  else
    row_pass<true>(kind + 1, d + 1, bed + 1, bed_lo + 1, sediment + 1, vx + 1, vy + 1, W - 2,
                   kStatsChunk, pw, pm, ps, e);
  MaterialRow& kept = material_rows_[static_cast<std::size_t>(y - 1)];
  if (!material_known) kept = {sum_lanes(pm) * a, sum_lanes(ps) * a};
  const double water = sum_lanes(pw) * a, material = kept.material, sed = kept.sediment;
  row.water = water;
  row.material = material;
  row.sediment = sed;

  // the largest depth is a Real's value (exact in double)
  const Real best_d = static_cast<Real>(e.max_depth);
  const double best_v2 = e.max_speed2;
  const int chunk_d = 1 + e.depth_chunk, chunk_v = 1 + e.speed_chunk;
  if (best_d > Real(-1)) {  // a cell beat the -1 a scan starts from
    int x = chunk_d;
    while (!(kind[x] == ERODEM_CELL_ACTIVE && d[x] == best_d)) ++x;
    row.max_depth = d[x];
    row.max_depth_cell = row_cell + x;
  }
  if (best_v2 > -1) {
    int x = chunk_v;
    while (!(kind[x] == ERODEM_CELL_ACTIVE && speed2(x) == best_v2)) ++x;
    row.max_speed2 = best_v2;
    row.max_speed_cell = row_cell + x;
    row.speed = std::hypot(static_cast<double>(vx[x]), static_cast<double>(vy[x]));
  }
  if (!(std::isfinite(water) && std::isfinite(material) && std::isfinite(sed) && e.min_depth >= 0))
    for (int x = 1; x < W - 1; ++x)
      if (kind[x] == ERODEM_CELL_ACTIVE && !cell::cell_state_ok(bed[x], d[x], sediment[x])) {
        row.bad_cell = row_cell + x;
        break;
      }
  return row;
}

template <class Real>
std::vector<double> CpuBackend<Real>::field(FieldId id) const {
  return field_rows(id, 0, ny_);
}

template <class Real>
std::vector<double> CpuBackend<Real>::field_rows(FieldId id, int row0, int row1) const {
  // this rank's rows of [row0, row1), then every rank's in row order
  OwnRows own = own_field_rows(id, row0, row1);
  if (band_.banded) return parallel::allgather(own.values);
  return std::move(own.values);
}

template <class Real>
OwnRows CpuBackend<Real>::own_field_rows(FieldId id, int row0, int row1) const {
  check_row_range(id, row0, row1, nx_, ny_);
  // the rows of [row0, row1) this rank owns (all of them in one process; DEM row r is padded
  // row r + 1 - band_.row0)
  const int y0 = std::max(band_.own0, row0 + 1 - band_.row0),
            y1 = std::min(band_.own1, row1 + 1 - band_.row0);
  OwnRows out;
  out.row0 = y1 > y0 ? y0 - 1 + band_.row0 : row0;
  out.row1 = y1 > y0 ? y1 - 1 + band_.row0 : row0;
  out.values.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(std::max(y1 - y0, 0)));
  if (!fields_.reads_zeros(id)) {  // a field not made yet: its zeros, without an array of them
    const Field* src = fields_.peek(id);
    for (int y = y0; y < y1; ++y)
      for (int c = 0; c < nx_; ++c)
        out.values[static_cast<std::size_t>(y - y0) * nx_ + c] = value_at(id, src, at(c + 1, y));
  }
  return out;
}

template <class Real>
void CpuBackend<Real>::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  set_field_rows(id, 0, ny_, values);
}

template <class Real>
void CpuBackend<Real>::set_field_rows(FieldId id, int row0, int row1,
                                      const std::vector<double>& values) {
  check_rows(id, row0, row1, values.size(), nx_, ny_);
  if (material_field(id)) material_known_ = false;       // the volumes summed again
  if (fields_.setting_keeps_unmade(id, values)) return;  // reads give these zeros already
  Field* dst = field_storage(id);
  if (!dst)
    throw Error(ExitCode::usage,
                fmt::format("field '{}' is derived and cannot be set", field_info(id).name));
  // Fields kept in two buffers get both, so the next step starts from the new values.
  Field* twin = fields_.twin(id);
  if (twin && twin->empty()) twin = nullptr;  // a field updated in place (bed_next_)
  // the DEM rows the padded raster holds (a band's own and halo rows in an MPI run)
  for (int y = 0; y < H_; ++y) {
    const int r = y + band_.row0 - 1;
    if (r < row0 || r >= row1) continue;
    for (int c = 0; c < nx_; ++c) {
      const auto p = at(c + 1, y);
      const double value = values[static_cast<std::size_t>(r - row0) * nx_ + c];
      const auto v = static_cast<Real>(value);
      (*dst)[p] = v;
      if (twin) (*twin)[p] = v;
      // a bed keeps what Real cannot hold in its residual (set bed_residual after the bed)
      if (id == FieldId::bed) bed_residual_[p] = static_cast<Real>(value - static_cast<double>(v));
    }
  }
  if (periodic_) {
    copy_periodic_columns(dst->data(), W_, H_);
    if (twin) copy_periodic_columns(twin->data(), W_, H_);
    if (id == FieldId::bed) copy_periodic_columns(bed_residual_.data(), W_, H_);
  }
}

template <class Real>
HostView CpuBackend<Real>::host_view(FieldId id) {
  Field* src = band_.banded ? nullptr : field_storage(id);  // a band holds part of the field
  if (!src) return {};
  // its writes come unannounced: the volumes are summed every time from now on
  if (src == &bed_ || src == &bed_residual_ || src == &sediment_) material_viewed_ = true;
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
