// erodem — the result file reader (results.hpp, docs/results.md): the grid, times and root
// attributes of a result file, its field snapshots, restart state, diagnostics and gauges.
#include <fmt/format.h>
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <system_error>

#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/results.hpp"
#include "erodem/schema.hpp"
#include "h5.hpp"

namespace erodem::io {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void not_ours(const std::string& path, const std::string& why) {
  throw Error(ExitCode::data, path + ": not an erodem result file (" + why + ")");
}

/// A 1-D dataset as doubles.
std::vector<double> read_doubles(hid_t loc, const std::string& name, const std::string& path) {
  H5Id ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT));
  if (!ds.valid()) not_ours(path, "no dataset " + name);
  H5Id space(H5Dget_space(ds));
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n < 0) not_ours(path, "unreadable dataset " + name);
  std::vector<double> v(static_cast<std::size_t>(n));
  if (n > 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
    throw Error(ExitCode::io, path + ": reading " + name + " failed" + h5_reason());
  return v;
}

}  // namespace

ResultReader::ResultReader(const std::string& path) : path_(path) {
  QuietH5 quiet;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(ExitCode::no_input, path + ": no such file");
  if (H5Fis_hdf5(path.c_str()) <= 0) not_ours(path, "not an HDF5 file");
  file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) throw Error(ExitCode::data, path + ": cannot open" + h5_open_reason(path));
  try {
    if (H5Aexists(file_, "erodem_version") <= 0) not_ours(path, "no erodem_version attribute");
    // Root attributes (text ones).
    H5Aiterate2(
        file_, H5_INDEX_NAME, H5_ITER_INC, nullptr,
        [](hid_t loc, const char* name, const H5A_info_t*, void* out) -> herr_t {
          std::string value;
          if (get_text(loc, name, value))
            (*static_cast<std::map<std::string, std::string>*>(out))[name] = value;
          return 0;
        },
        &attributes_);
    const bool geographic = exists(file_, "lon") && exists(file_, "lat");
    const char* xname = geographic ? "lon" : "x";
    const char* yname = geographic ? "lat" : "y";
    if (!exists(file_, "time") || !exists(file_, xname) || !exists(file_, yname))
      not_ours(path, "no time, y and x coordinates");
    times_ = read_doubles(file_, "time", path);
    const auto xs = read_doubles(file_, xname, path);
    const auto ys = read_doubles(file_, yname, path);
    if (xs.empty() || ys.empty()) not_ours(path, "empty grid");
    Grid& g = grid_;
    g.nx = static_cast<int>(xs.size());
    g.ny = static_cast<int>(ys.size());
    g.georef.is_geographic = geographic;
    bool have_transform = false;
    if (exists(file_, "crs")) {
      H5Id crs(H5Dopen2(file_, "crs", H5P_DEFAULT));
      std::string text;
      if (crs.valid() && get_text(crs, "crs_wkt", text)) g.georef.crs_wkt = text;
      if (crs.valid() && get_text(crs, "GeoTransform", text)) {
        std::istringstream in(text);
        auto& t = g.georef.transform;
        have_transform = static_cast<bool>(in >> t[0] >> t[1] >> t[2] >> t[3] >> t[4] >> t[5]);
      }
    }
    if (!have_transform) {  // from the cell centres
      const double dx = g.nx > 1 ? (xs.back() - xs.front()) / (g.nx - 1) : 1.0;
      const double dy = g.ny > 1 ? (ys.back() - ys.front()) / (g.ny - 1) : -1.0;
      g.georef.transform = {xs.front() - 0.5 * dx, dx, 0.0, ys.front() - 0.5 * dy, 0.0, dy};
    }
    g.georef.has_transform = true;
    const auto rows = static_cast<std::size_t>(g.ny);
    if (exists(file_, "cell_dx") && exists(file_, "cell_dy") && exists(file_, "cell_area")) {
      g.dx = read_doubles(file_, "cell_dx", path);
      g.dy = read_doubles(file_, "cell_dy", path);
      g.area = read_doubles(file_, "cell_area", path);
      if (g.dx.size() != rows || g.dy.size() != rows || g.area.size() != rows)
        not_ours(path, "cell sizes do not match the grid");
    } else {  // from the transform (projected grids in metres)
      const double dx = std::abs(g.georef.transform[1]), dy = std::abs(g.georef.transform[5]);
      g.dx.assign(rows, dx);
      g.dy.assign(rows, dy);
      g.area.assign(rows, dx * dy);
    }
  } catch (...) {
    H5Fclose(file_);
    throw;
  }
}

ResultReader::~ResultReader() {
  if (file_ >= 0) H5Fclose(file_);
}

std::string ResultReader::attribute(const std::string& name) const {
  const auto it = attributes_.find(name);
  return it == attributes_.end() ? std::string() : it->second;
}

std::vector<std::string> ResultReader::fields() const {
  QuietH5 quiet;
  struct Walk {
    std::vector<std::string> names;
  } walk;
  const auto visit = [](hid_t loc, const char* name, const H5L_info_t*, void* data) -> herr_t {
    auto* w = static_cast<Walk*>(data);
    H5Id ds(H5Dopen2(loc, name, H5P_DEFAULT));  // fails (quietly) for groups
    if (!ds.valid()) return 0;
    H5Id space(H5Dget_space(ds));
    if (H5Sget_simple_extent_ndims(space) == 3) w->names.emplace_back(name);
    return 0;
  };
  if (H5Literate(file_, H5_INDEX_CRT_ORDER, H5_ITER_INC, nullptr, visit, &walk) < 0) {
    walk.names.clear();
    H5Literate(file_, H5_INDEX_NAME, H5_ITER_INC, nullptr, visit, &walk);
  }
  return walk.names;
}

std::size_t ResultReader::nearest_time_index(double time) const {
  if (times_.empty()) throw Error(ExitCode::data, path_ + ": holds no snapshot");
  std::size_t best = 0;
  for (std::size_t k = 1; k < times_.size(); ++k)
    if (std::abs(times_[k] - time) < std::abs(times_[best] - time)) best = k;
  return best;
}

std::vector<float> ResultReader::read(const std::string& name, double time) const {
  return read_index(name, nearest_time_index(time));
}

std::vector<float> ResultReader::read_index(const std::string& name, std::size_t index) const {
  QuietH5 quiet;
  if (index >= times_.size())
    throw Error(ExitCode::usage,
                fmt::format("{}: no snapshot {} (the file holds {})", path_, index, times_.size()));
  const auto names = fields();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw Error(ExitCode::data, path_ + ": no field '" + name + "' (fields: " + list + ")");
  }
  H5Id ds(H5Dopen2(file_, name.c_str(), H5P_DEFAULT));
  H5Id space(H5Dget_space(ds));
  std::array<hsize_t, 3> dims{};
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  if (dims[1] != static_cast<hsize_t>(grid_.ny) || dims[2] != static_cast<hsize_t>(grid_.nx) ||
      dims[0] <= index)
    throw Error(ExitCode::data, path_ + ": field '" + name + "' does not match the grid");
  const std::array<hsize_t, 3> start{index, 0, 0}, count{1, dims[1], dims[2]};
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  H5Id mem(H5Screate_simple(3, count.data(), nullptr));
  std::vector<float> values(grid_.cells());
  if (H5Dread(ds, H5T_NATIVE_FLOAT, mem, space, H5P_DEFAULT, values.data()) < 0)
    throw Error(ExitCode::io, path_ + ": reading " + name + " failed" + h5_reason());
  return values;
}

bool ResultReader::has_restart_state() const {
  QuietH5 quiet;
  return exists(file_, "restart/steps");
}

std::vector<double> ResultReader::restart_times() const {
  QuietH5 quiet;
  if (!has_restart_state()) return {};
  if (exists(file_, "restart/time")) return read_doubles(file_, "restart/time", path_);
  // before 2026-11-27: a state at every snapshot
  const auto steps = read_doubles(file_, "restart/steps", path_);
  return {times_.begin(), times_.begin() + std::min(times_.size(), steps.size())};
}

namespace {

/// A state field's dataset in a result file and its row at restart state `index`; no dataset
/// where the file lacks a field that may start at zeros. Not erodem's (Error(data), naming the
/// dataset) where it is missing or does not fit the grid and the stored times.
struct RestartDataset {
  H5Id dataset;
  hsize_t row = 0;
};

RestartDataset restart_dataset(hid_t file, const std::string& path, const Grid& grid,
                               std::size_t index, FieldId id) {
  RestartDataset out;
  const std::string name = std::string("restart/") + field_info(id).name;
  if (field_info(id).restart_zero_if_absent && !exists(file, name)) return out;  // zeros
  // a field stored once per value: its row at this time in NAME_row
  hsize_t row = index;
  if (exists(file, name + "_row")) {
    const auto rows = read_doubles(file, name + "_row", path);
    if (index >= rows.size() || !(rows[index] >= 0))
      not_ours(path, name + "_row does not cover the stored times");
    row = static_cast<hsize_t>(rows[index]);
  }
  H5Id ds(H5Dopen2(file, name.c_str(), H5P_DEFAULT));
  if (!ds.valid()) not_ours(path, "no dataset " + name);
  H5Id space(H5Dget_space(ds));
  std::array<hsize_t, 3> dims{};
  if (H5Sget_simple_extent_ndims(space) != 3) not_ours(path, name + " is not (time, y, x)");
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  if (dims[1] != static_cast<hsize_t>(grid.ny) || dims[2] != static_cast<hsize_t>(grid.nx) ||
      dims[0] <= row)
    not_ours(path, name + " does not match the grid and the stored times");
  out.dataset = std::move(ds);
  out.row = row;
  return out;
}

}  // namespace

RestartPoint ResultReader::restart_point(std::size_t index) const {
  RestartPoint p = restart_header(index);
  for (FieldId id : state_fields()) p.fields.push_back(restart_rows(index, id, 0, grid_.ny));
  return p;
}

RestartPoint ResultReader::restart_header(std::size_t index) const {
  QuietH5 quiet;
  if (!has_restart_state())
    throw Error(ExitCode::data, path_ +
                                    ": holds no restart state (it was written with "
                                    "output.restart_state = false, or by an older erodem)");
  const auto times = restart_times();
  const auto steps = read_doubles(file_, "restart/steps", path_);
  if (index >= times.size() || index >= steps.size())
    throw Error(ExitCode::usage, fmt::format("{}: no restart state {} (the file holds {})", path_,
                                             index, std::min(times.size(), steps.size())));
  RestartPoint p;
  p.time = times[index];
  p.steps = static_cast<long>(steps[index]);
  // Files of erodem before the bed residual and the moved volumes (2026-11-25) or the snow pack
  // (2026-11-26) lack those: they start at 0 (the residual then holds nothing yet, as in any
  // new run; a run without snow has none).
  for (const auto& e : ledger_entries()) {
    const std::string name = std::string("restart/ledger_") + e.name;
    p.ledger.*e.member =
        exists(file_, name) || !e.zero_if_absent ? read_doubles(file_, name, path_).at(index) : 0.0;
  }
  // Before the pack held liquid water (snowfall, 2026-11-26) its melt went straight into the
  // depth: what such a file calls snow_melted is the pack's runoff of the water closure now.
  if (!exists(file_, "restart/ledger_snow_runoff")) p.ledger.snow_runoff = p.ledger.snow_melted;
  // every field's dataset there and fitting the grid before any is read (restart_rows)
  for (FieldId id : state_fields()) restart_dataset(file_, path_, grid_, index, id);
  return p;
}

std::vector<double> ResultReader::restart_rows(std::size_t index, FieldId id, int row0,
                                               int row1) const {
  QuietH5 quiet;
  if (row0 < 0 || row1 > grid_.ny || row1 < row0)
    throw Error(ExitCode::internal, fmt::format("{}: restart rows [{}, {}) of a grid of {} rows",
                                                path_, row0, row1, grid_.ny));
  const RestartDataset d = restart_dataset(file_, path_, grid_, index, id);
  std::vector<double> values(static_cast<std::size_t>(row1 - row0) * grid_.nx, 0.0);
  if (!d.dataset.valid() || values.empty()) return values;  // a field the file may lack: zeros
  H5Id space(H5Dget_space(d.dataset));
  const std::array<hsize_t, 3> start{d.row, static_cast<hsize_t>(row0), 0},
      count{1, static_cast<hsize_t>(row1 - row0), static_cast<hsize_t>(grid_.nx)};
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  H5Id mem(H5Screate_simple(3, count.data(), nullptr));
  if (H5Dread(d.dataset, H5T_NATIVE_DOUBLE, mem, space, H5P_DEFAULT, values.data()) < 0)
    throw Error(ExitCode::io,
                path_ + ": reading restart/" + field_info(id).name + " failed" + h5_reason());
  return values;
}

std::vector<Diagnostics> ResultReader::diagnostics() const {
  QuietH5 quiet;
  if (!exists(file_, "diagnostics")) return {};
  std::vector<Diagnostics> rows;
  for (const auto& s : diagnostics_series()) {
    const auto v = read_doubles(file_, std::string("diagnostics/") + s.name, path_);
    if (rows.empty()) rows.resize(v.size());
    if (v.size() != rows.size())
      throw Error(ExitCode::data, path_ + ": diagnostics series of different lengths");
    for (std::size_t r = 0; r < v.size(); ++r) rows[r].*s.member = v[r];
  }
  return rows;
}

GaugeSeries ResultReader::gauges() const {
  QuietH5 quiet;
  GaugeSeries out;
  if (!exists(file_, "gauges")) return out;
  out.x = read_doubles(file_, "gauges/x", path_);
  out.y = read_doubles(file_, "gauges/y", path_);
  out.time = read_doubles(file_, "gauges/time", path_);
  const std::size_t n = out.x.size();
  std::vector<std::vector<double>>* series[] = {&out.water_depth, &out.water_level, &out.speed};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto flat = read_doubles(file_, std::string("gauges/") + kGaugeSeries[k], path_);
    for (std::size_t r = 0; n > 0 && r < flat.size() / n; ++r)
      series[k]->emplace_back(flat.begin() + static_cast<std::ptrdiff_t>(r * n),
                              flat.begin() + static_cast<std::ptrdiff_t>((r + 1) * n));
  }
  return out;
}

}  // namespace erodem::io
