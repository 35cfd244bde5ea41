#include "cpu/cpu_backend.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "common/stats.h"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"

namespace erodem {

template <class Real>
CpuBackend<Real>::CpuBackend(const Terrain& terrain, const Params& params)
    : params_(params),
      nx_(terrain.grid.nx),
      ny_(terrain.grid.ny),
      W_(terrain.grid.nx + 2),
      H_(terrain.grid.ny + 2) {
  const auto& g = terrain.grid;
  g.validate();
  const auto n = static_cast<std::size_t>(W_) * H_;
  const std::size_t cells = g.cells();
  auto check_size = [&](const std::vector<double>& v, const char* what) {
    if (!v.empty() && v.size() != cells)
      throw Error(ExitCode::data,
                  fmt::format("{}: {} values for a grid of {} x {}", what, v.size(), g.nx, g.ny));
  };
  check_size(terrain.bed, "bed");
  if (terrain.bed.size() != cells) throw Error(ExitCode::data, "bed: missing");
  check_size(terrain.water_depth, "initial water depth");
  check_size(terrain.manning_n, "flow.manning_n");
  check_size(terrain.hardness, "erosion.hardness");
  check_size(terrain.rain_factor, "rain.raster");
#ifdef _OPENMP
  threads_ = params.numerics.threads > 0 ? params.numerics.threads : omp_get_max_threads();
#else
  threads_ = 1;
#endif

  // Geometry per padded row; halo rows repeat their neighbours.
  dx_.resize(H_);
  dy_.resize(H_);
  area_.resize(H_);
  for (int y = 0; y < H_; ++y) {
    const int r = std::clamp(y - 1, 0, ny_ - 1);
    dx_[y] = static_cast<Real>(g.dx[r]);
    dy_[y] = static_cast<Real>(g.dy[r]);
    area_[y] = static_cast<Real>(g.area[r]);
  }

  // Cell kinds: DEM cells active or nodata (wall or sea); halo by the edge's boundary kind.
  const double sea = params.boundary.sea_level;
  kind_.assign(n, ERODEM_CELL_WALL);
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c) {
      const auto i = static_cast<std::size_t>(r) * nx_ + c;
      kind_[at(c + 1, r + 1)] = terrain.active(i)                           ? ERODEM_CELL_ACTIVE
                                : params.boundary.nodata == NodataKind::sea ? ERODEM_CELL_FIXED
                                                                            : ERODEM_CELL_WALL;
    }
  auto edge_kind = [](BoundaryKind b) {
    switch (b) {
      case BoundaryKind::open:
        return Kind{ERODEM_CELL_OPEN};
      case BoundaryKind::fixed_level:
        return Kind{ERODEM_CELL_FIXED};
      case BoundaryKind::closed:
        break;
    }
    return Kind{ERODEM_CELL_WALL};
  };
  for (int y = 1; y <= ny_; ++y) {
    if (kind_[at(1, y)] == ERODEM_CELL_ACTIVE) kind_[at(0, y)] = edge_kind(params.boundary.west);
    if (kind_[at(nx_, y)] == ERODEM_CELL_ACTIVE)
      kind_[at(nx_ + 1, y)] = edge_kind(params.boundary.east);
  }
  for (int x = 1; x <= nx_; ++x) {
    if (kind_[at(x, 1)] == ERODEM_CELL_ACTIVE) kind_[at(x, 0)] = edge_kind(params.boundary.north);
    if (kind_[at(x, ny_)] == ERODEM_CELL_ACTIVE)
      kind_[at(x, ny_ + 1)] = edge_kind(params.boundary.south);
  }

  // Bed and initial water (computed in double, then rounded once).
  std::vector<double> bed(n, 0.0), depth(n, 0.0);
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c) {
      const auto i = static_cast<std::size_t>(r) * nx_ + c;
      const auto p = at(c + 1, r + 1);
      if (kind_[p] != ERODEM_CELL_ACTIVE) continue;
      bed[p] = terrain.bed[i];
      if (!terrain.water_depth.empty())
        depth[p] = terrain.water_depth[i];
      else if (params.initial.water_level)
        depth[p] = std::max(0.0, *params.initial.water_level - bed[p]);
      else
        depth[p] = params.initial.water_depth.value;
    }
  // Nodata cells: sea ghosts hold the sea over a bed no higher than their active neighbours.
  for (int y = 1; y <= ny_; ++y)
    for (int x = 1; x <= nx_; ++x) {
      const auto p = at(x, y);
      if (kind_[p] == ERODEM_CELL_ACTIVE) continue;
      double low = sea;
      for (auto q : {p - 1, p + 1, p - W_, p + W_})
        if (kind_[q] == ERODEM_CELL_ACTIVE) low = std::min(low, bed[q]);
      bed[p] = kind_[p] == ERODEM_CELL_FIXED ? low : 0.0;
      depth[p] = kind_[p] == ERODEM_CELL_FIXED ? sea - low : 0.0;
    }
  auto to_real = [](const std::vector<double>& v) { return std::vector<Real>(v.begin(), v.end()); };
  bed_ = to_real(bed);
  depth_ = to_real(depth);
  bed_next_ = bed_;
  bed0_ = bed_;
  depth_next_ = depth_;
  sediment_.assign(n, Real(0));
  sediment_next_ = sediment_;
  for (int k = 0; k < 4; ++k) {
    flux_[k].assign(n, Real(0));
    flux_next_[k].assign(n, Real(0));
  }
  velocity_x_.assign(n, Real(0));
  velocity_y_.assign(n, Real(0));
  thermal_share_.assign(n, Real(0));
  wetness_ = depth_;

  // Rasters or scalars; halo cells copy the nearest DEM cell (Manning n is read at faces).
  auto raster_or = [&](const std::vector<double>& raster, double scalar) {
    std::vector<Real> out(n, static_cast<Real>(scalar));
    if (raster.empty()) return out;
    for (int y = 0; y < H_; ++y)
      for (int x = 0; x < W_; ++x) {
        const int r = std::clamp(y - 1, 0, ny_ - 1), c = std::clamp(x - 1, 0, nx_ - 1);
        out[at(x, y)] = static_cast<Real>(raster[static_cast<std::size_t>(r) * nx_ + c]);
      }
    return out;
  };
  manning_ = raster_or(terrain.manning_n, params.flow.manning_n.value);
  hardness_ = raster_or(terrain.hardness, params.erosion.hardness.value);
  rain_factor_ = raster_or(terrain.rain_factor, 1.0);
  row_sums_a_.assign(H_, 0.0);
  row_sums_b_.assign(H_, 0.0);
  run_boundary();
}

template <class Real>
std::string CpuBackend<Real>::device() const {
  return fmt::format("CPU reference, {}, {} thread{}", sizeof(Real) == 4 ? "float32" : "float64",
                     threads_, threads_ == 1 ? "" : "s");
}

template <class Real>
double CpuBackend<Real>::sum_rows(const std::vector<double>& rows) {
  double s = 0.0;
  for (double v : rows) s += v;
  return s;
}

template <class Real>
void CpuBackend<Real>::run(Process p, const StepInputs& in, StepTally& tally) {
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
      run_water(dt, tally);
      break;
    case Process::erosion:
      run_erosion(dt);
      break;
    case Process::transport:
      run_transport(dt, tally);
      break;
    case Process::thermal:
      run_thermal(dt);
      break;
    case Process::evaporation:
      run_evaporation(dt, tally);
      break;
  }
}

template <class Real>
FieldStats CpuBackend<Real>::stats() {
  struct Row {
    double water = 0, material = 0, sediment = 0, max_d = -1, max_v = -1;
    std::int64_t arg_d = -1, arg_v = -1, bad = -1;
  };
  std::vector<Row> rows(H_);
  for_rows(1, H_ - 1, [&](int y) {
    Row row;
    const double a = area_[y];
    for (int x = 1; x < W_ - 1; ++x) {
      const auto i = at(x, y);
      if (kind_[i] != ERODEM_CELL_ACTIVE) continue;
      const Real d = depth_[i], b = bed_[i], s = sediment_[i];
      const std::int64_t cell = static_cast<std::int64_t>(y - 1) * nx_ + (x - 1);
      if (row.bad < 0 && !cell::cell_state_ok(b, d, s)) row.bad = cell;
      row.water += static_cast<double>(d) * a;
      row.material += (static_cast<double>(b) + static_cast<double>(s)) * a;
      row.sediment += static_cast<double>(s) * a;
      if (d > row.max_d) {
        row.max_d = d;
        row.arg_d = cell;
      }
      const double v =
          std::hypot(static_cast<double>(velocity_x_[i]), static_cast<double>(velocity_y_[i]));
      if (v > row.max_v) {
        row.max_v = v;
        row.arg_v = cell;
      }
    }
    rows[y] = row;
  });
  FieldStats st;
  st.max_depth = 0.0;
  st.max_speed = 0.0;
  for (const auto& row : rows) {
    st.water_volume += row.water;
    st.material_volume += row.material;
    st.sediment_volume += row.sediment;
    if (row.max_d > st.max_depth || (st.max_depth_cell < 0 && row.arg_d >= 0)) {
      st.max_depth = std::max(0.0, row.max_d);
      st.max_depth_cell = row.arg_d;
    }
    if (row.max_v > st.max_speed || (st.max_speed_cell < 0 && row.arg_v >= 0)) {
      st.max_speed = std::max(0.0, row.max_v);
      st.max_speed_cell = row.arg_v;
    }
    if (st.bad_cell < 0 && row.bad >= 0) st.bad_cell = row.bad;
  }
  return st;
}

template <class Real>
std::vector<Real>* CpuBackend<Real>::field_storage(FieldId id) {
  switch (id) {
    case FieldId::bed:
      return &bed_;
    case FieldId::water_depth:
      return &depth_;
    case FieldId::sediment:
      return &sediment_;
    case FieldId::velocity_x:
      return &velocity_x_;
    case FieldId::velocity_y:
      return &velocity_y_;
    case FieldId::flux_left:
      return &flux_[ERODEM_LEFT];
    case FieldId::flux_right:
      return &flux_[ERODEM_RIGHT];
    case FieldId::flux_top:
      return &flux_[ERODEM_TOP];
    case FieldId::flux_bottom:
      return &flux_[ERODEM_BOTTOM];
    case FieldId::hardness:
      return &hardness_;
    case FieldId::wetness:
      return &wetness_;
    case FieldId::manning_n:
      return &manning_;
    case FieldId::erosion:
      return nullptr;
  }
  return nullptr;
}

template <class Real>
std::vector<double> CpuBackend<Real>::field(FieldId id) const {
  std::vector<double> out(static_cast<std::size_t>(nx_) * ny_);
  auto* self = const_cast<CpuBackend*>(this);
  const std::vector<Real>* src = self->field_storage(id);
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c) {
      const auto p = at(c + 1, r + 1);
      out[static_cast<std::size_t>(r) * nx_ + c] =
          src ? static_cast<double>((*src)[p])
              : static_cast<double>(bed0_[p]) - static_cast<double>(bed_[p]);
    }
  return out;
}

template <class Real>
void CpuBackend<Real>::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  std::vector<Real>* dst = field_storage(id);
  if (!dst) throw Error(ExitCode::usage, "field 'erosion' is derived and cannot be set");
  // Fields kept in two buffers get both, so the next step starts from the new values.
  std::vector<Real>* twin = id == FieldId::bed           ? &bed_next_
                            : id == FieldId::water_depth ? &depth_next_
                            : id == FieldId::sediment    ? &sediment_next_
                                                         : nullptr;
  for (int r = 0; r < ny_; ++r)
    for (int c = 0; c < nx_; ++c) {
      const auto p = at(c + 1, r + 1);
      const auto v = static_cast<Real>(values[static_cast<std::size_t>(r) * nx_ + c]);
      (*dst)[p] = v;
      if (twin) (*twin)[p] = v;
    }
}

template class CpuBackend<float>;
template class CpuBackend<double>;

std::unique_ptr<Backend> make_cpu_backend(const Terrain& terrain, const Params& params) {
  if (params.numerics.precision == Precision::float64)
    return std::make_unique<CpuBackend<double>>(terrain, params);
  return std::make_unique<CpuBackend<float>>(terrain, params);
}

std::unique_ptr<Backend> make_backend(const std::string& name, const Terrain& terrain,
                                      const Params& params) {
  if (name == "cpu") return make_cpu_backend(terrain, params);
  if (name == "opencl") return make_opencl_backend(terrain, params);
  if (name == "auto") {
    // A GPU OpenCL device, else OpenCL on PoCL, else the CPU reference. The OpenCL backend
    // runs float32 only; ERODEM_OPENCL_DEVICE, when set, chooses the OpenCL device.
    if (params.numerics.precision == Precision::float32) {
      const auto devices = list_opencl_devices();
      const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
      const bool any_gpu = std::any_of(devices.begin(), devices.end(),
                                       [](const ClDeviceInfo& d) { return d.gpu(); });
      const bool pocl = std::any_of(devices.begin(), devices.end(), [](const ClDeviceInfo& d) {
        return d.platform.find("Portable Computing Language") != std::string::npos ||
               d.vendor.find("pocl") != std::string::npos;
      });
      if ((env && *env && !devices.empty()) || any_gpu || pocl)
        return make_opencl_backend(terrain, params);
    }
    return make_cpu_backend(terrain, params);
  }
  throw Error(ExitCode::usage, "backend '" + name + "': expected auto, cpu or opencl" +
                                   (opencl_available() ? "" : " (no OpenCL device here)"));
}

}  // namespace erodem
