// erodem viewer — a result file or DEM as the viewer sees it (view_data.hpp).
#include "erodem/viz/view_data.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>

#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/results.hpp"

namespace erodem::viz {

namespace {

/// Whether the file starts with the HDF5 signature (a result file).
bool is_hdf5(const std::string& path) {
  static const char signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  return in.read(head, 8) && std::memcmp(head, signature, 8) == 0;
}

ColorMap map_of(const std::string& name) {
  if (name == "bed" || name == "initial_bed") return ColorMap::terrain;
  if (name == "water_depth" || name == "wetness") return ColorMap::water;
  if (name == "sediment") return ColorMap::sediment;
  if (name == "speed") return ColorMap::speed;
  if (name == "erosion" || name == "velocity_x" || name == "velocity_y" ||
      name.rfind("flux_", 0) == 0)
    return ColorMap::diverging;
  if (name == "terrain_class") return ColorMap::classes;
  return ColorMap::sediment;
}

/// The most cached fields kept (each nx * ny floats).
constexpr std::size_t kCacheSize = 12;

}  // namespace

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

ViewData::ViewData(const std::string& path, const DemOptions& dem) : path_(path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(ExitCode::no_input, path + ": no such file");
  if (is_hdf5(path)) {
    reader_ = std::make_unique<io::ResultReader>(path);
    grid_ = reader_->grid();
    times_ = reader_->times();
    if (times_.empty()) throw Error(ExitCode::data, path + ": holds no snapshot");
    stored_ = reader_->fields();
  } else {
    Params::Dem p;
    p.path = path;
    p.cell_size = dem.cell_size;
    p.z_scale = dem.z_scale;
    p.crs = dem.crs;
    Terrain t;
    try {
      t = io::read_dem(p);
    } catch (const Error& e) {
      if (e.code() != ExitCode::config) throw;
      // The config keys read_dem names are options here.
      throw Error(ExitCode::usage,
                  std::string(e.what()) + " (erodem view: --cell-size M, --crs CRS, --z-scale S)");
    }
    grid_ = t.grid;
    dem_bed_.assign(t.bed.begin(), t.bed.end());
    times_ = {0.0};
    stored_ = {"bed"};
  }
  for (const auto& name : stored_) {
    ViewField f;
    f.name = name;
    f.map = map_of(name);
    try {
      const auto& info = field_info(name);
      f.units = info.units;
      f.long_name = info.long_name;
    } catch (const Error&) {
      // A field this build does not know: shown without units.
    }
    fields_.push_back(f);
  }
  if (stored("velocity_x") && stored("velocity_y"))
    fields_.push_back({"speed", "m s-1", "flow speed |v|", ColorMap::speed, false});
  if (!stored("erosion") && stored("bed") && times_.size() > 1)
    fields_.push_back({"erosion", "m",
                       "bed lowering since the first snapshot (negative = deposition)",
                       ColorMap::diverging, false});
  // the model's classes where the run stored them (terrain_classes.enabled), else derived
  if (stored("bed") && !stored("terrain_class"))
    fields_.push_back({"terrain_class", "1", "terrain class (grass, mud, rock, snow, water)",
                       ColorMap::classes, false});
}

ViewData::~ViewData() = default;

bool ViewData::stored(const std::string& name) const {
  return std::find(stored_.begin(), stored_.end(), name) != stored_.end();
}

bool ViewData::has_field(const std::string& name) const {
  return std::any_of(fields_.begin(), fields_.end(),
                     [&](const ViewField& f) { return f.name == name; });
}

const ViewField& ViewData::field(const std::string& name) const {
  for (const auto& f : fields_)
    if (f.name == name) return f;
  std::vector<std::string> names;
  for (const auto& f : fields_) names.push_back(f.name);
  throw Error(ExitCode::data,
              fmt::format("{}: no field '{}' (available: {})", path_, name, join_names(names)));
}

std::size_t ViewData::time_index(double time) const {
  for (std::size_t k = 0; k < times_.size(); ++k)
    if (std::abs(times_[k] - time) <= 1e-9 * std::max(1.0, std::abs(time))) return k;
  std::string list;
  for (std::size_t k = 0; k < times_.size() && k < 12; ++k)
    list += (k ? ", " : "") + fmt::format("{:g}", times_[k]);
  if (times_.size() > 12) list += fmt::format(", ... ({} in all)", times_.size());
  throw Error(ExitCode::data,
              fmt::format("{}: no snapshot at t = {:g} s (stored: {} s)", path_, time, list));
}

std::size_t ViewData::nearest_time_index(double time) const {
  if (!std::isfinite(time))
    throw Error(ExitCode::usage, fmt::format("--time: expected a finite time (s), got {}", time));
  double gap = 0.0;
  for (std::size_t k = 1; k < times_.size(); ++k) gap = std::max(gap, times_[k] - times_[k - 1]);
  const double slack = std::max(gap, 1e-9 * std::max(1.0, std::abs(time)));
  if (time < times_.front() - slack || time > times_.back() + slack)
    throw Error(ExitCode::data,
                fmt::format("{}: t = {:g} s is outside the stored times ({:g} .. {:g} s, {} "
                            "snapshot{})",
                            path_, time, times_.front(), times_.back(), times_.size(),
                            times_.size() == 1 ? "" : "s"));
  std::size_t best = 0;
  for (std::size_t k = 1; k < times_.size(); ++k)
    if (std::abs(times_[k] - time) < std::abs(times_[best] - time)) best = k;
  return best;
}

std::size_t ViewData::snapshot_index(long k) const {
  const long n = static_cast<long>(times_.size());
  if (k < -n || k >= n)
    throw Error(ExitCode::usage,
                fmt::format("--snapshot {}: out of range ({} snapshot{}: 0..{}, or -{}..-1 from "
                            "the end)",
                            k, n, n == 1 ? "" : "s", n - 1, n));
  return static_cast<std::size_t>(k < 0 ? n + k : k);
}

bool ViewData::bed_varies() const {
  return reader_ && stored("bed") && times_.size() > 1;
}

const std::vector<float>& ViewData::bed(std::size_t index) {
  if (!reader_) return dem_bed_;
  if (stored("bed")) return values("bed", index);
  if (stored("initial_bed")) return values("initial_bed", 0);
  throw Error(ExitCode::data, path_ + ": stores no 'bed' field; the viewer needs the bed");
}

const std::vector<float>& ViewData::values(const std::string& name, std::size_t index) {
  field(name);  // unknown -> Error
  if (index >= times_.size())
    throw Error(ExitCode::usage,
                fmt::format("snapshot index {} out of range (0..{})", index, times_.size() - 1));
  const auto key = std::make_pair(name, index);
  auto it = cache_.find(key);
  if (it != cache_.end()) return it->second;
  std::vector<float> v = compute(name, index);
  if (cache_order_.size() >= kCacheSize) {
    cache_.erase(cache_order_.front());
    cache_order_.erase(cache_order_.begin());
  }
  cache_order_.push_back(key);
  return cache_[key] = std::move(v);
}

std::vector<float> ViewData::compute(const std::string& name, std::size_t index) {
  if (!reader_) {
    if (name == "bed") return dem_bed_;
    if (name == "terrain_class") return classify_terrain(grid_, dem_bed_, {}, class_rule);
  }
  if (stored(name)) return reader_->read_index(name, index);
  if (name == "speed") {
    std::vector<float> u = reader_->read_index("velocity_x", index);
    const std::vector<float> v = reader_->read_index("velocity_y", index);
    for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::hypot(u[i], v[i]);
    return u;
  }
  if (name == "erosion") {
    std::vector<float> first = reader_->read_index("bed", 0);
    const std::vector<float> now = reader_->read_index("bed", index);
    for (std::size_t i = 0; i < first.size(); ++i) first[i] -= now[i];
    return first;
  }
  // terrain_class
  const std::vector<float> b = reader_->read_index("bed", index);
  std::vector<float> wet;
  if (stored("wetness"))
    wet = reader_->read_index("wetness", index);
  else if (stored("water_depth"))
    wet = reader_->read_index("water_depth", index);
  std::vector<float> snow;
  if (stored("snow")) snow = reader_->read_index("snow", index);
  return classify_terrain(grid_, b, wet, class_rule, snow);
}

namespace {

/// Cell (col, row) of `grid` at `time` (s), its centre in the grid's coordinates, no values yet.
CellValues cell_at(const Grid& grid, int col, int row, double time) {
  CellValues c;
  c.col = col;
  c.row = row;
  const auto p = grid.cell_center(col, row);
  c.x = p[0];
  c.y = p[1];
  c.time = time;
  return c;
}

}  // namespace

CellValues ViewData::cell_values(int col, int row, std::size_t index) {
  CellValues c = cell_at(grid_, col, row, times_.at(index));
  const std::size_t i = static_cast<std::size_t>(row) * grid_.nx + col;
  for (const auto& f : fields_) {
    // Copy the value before the next values() call can evict the vector.
    const double v = values(f.name, index)[i];
    c.values.emplace_back(f.name, v);
  }
  return c;
}

std::vector<CellValues> ViewData::cell_series(int col, int row,
                                              const std::vector<std::string>& names) {
  const std::size_t i = static_cast<std::size_t>(row) * grid_.nx + col;
  std::vector<std::string> wanted = names;
  if (wanted.empty())
    for (const auto& f : fields_) wanted.push_back(f.name);
  for (const auto& n : wanted) field(n);  // unknown -> Error
  std::vector<CellValues> series;
  for (std::size_t k = 0; k < times_.size(); ++k) {
    CellValues c = cell_at(grid_, col, row, times_[k]);
    for (const auto& n : wanted) {
      const auto it = cache_.find(std::make_pair(n, k));
      const double v = it != cache_.end() ? it->second[i] : compute(n, k)[i];
      c.values.emplace_back(n, v);
    }
    series.push_back(std::move(c));
  }
  return series;
}

std::array<double, 2> ViewData::held_color_range(const std::string& name, ColorMap map) {
  field(name);  // unknown -> Error
  const auto key = std::make_pair(name, map);
  if (auto it = held_ranges_.find(key); it != held_ranges_.end()) return it->second;
  // The values of every snapshot pooled (every k-th cell when that would pass kPoolValues),
  // and the map's range of the pool: the percentiles of the whole run. (A union of the
  // snapshots' own ranges would let an early snapshot with a few large values, such as
  // the first slope collapses, set the range for the whole run.)
  constexpr std::size_t kPoolValues = 4'000'000;
  const std::size_t cells = static_cast<std::size_t>(grid_.nx) * static_cast<std::size_t>(grid_.ny);
  const std::size_t n = map == ColorMap::classes ? 1 : times_.size();
  const std::size_t stride = std::max<std::size_t>(1, (n * cells + kPoolValues - 1) / kPoolValues);
  // The minimum and maximum are exact (a sampled pool could miss the extreme cell and then
  // mark the bar as clipped where nothing is).
  std::vector<float> pool;
  pool.reserve(n * ((cells + stride - 1) / stride));
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t k = 0; k < n; ++k) {
    const auto it = cache_.find(std::make_pair(name, k));
    const std::vector<float> computed =
        it != cache_.end() ? std::vector<float>{} : compute(name, k);
    const std::vector<float>& v = it != cache_.end() ? it->second : computed;
    for (std::size_t i = 0; i < v.size(); i += stride) pool.push_back(v[i]);
    for (float x : v)
      if (std::isfinite(x)) {
        lo = std::min(lo, static_cast<double>(x));
        hi = std::max(hi, static_cast<double>(x));
      }
  }
  std::optional<std::array<double, 2>> r = data_color_range(map, pool);
  if (r && map != ColorMap::diverging && map != ColorMap::classes) {
    (*r)[0] = lo;
    if (map == ColorMap::terrain) (*r)[1] = hi;
  }
  if (!r) r = color_range(map, values(name, times_.size() - 1));
  return held_ranges_[key] = *r;
}

std::string ViewData::describe() const {
  return fmt::format("{}: {} x {} cells, {}, {} snapshot{}", path_, grid_.nx, grid_.ny,
                     grid_.georef.is_geographic     ? "geographic (lon/lat)"
                     : grid_.georef.crs_wkt.empty() ? "no CRS (metres)"
                                                    : "projected",
                     times_.size(), times_.size() == 1 ? "" : "s");
}

}  // namespace erodem::viz
