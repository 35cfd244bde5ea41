// erodem viewer — what the viewer shows: a result file's (or a DEM's) fields over time.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/viz/colormap.hpp"
#include "erodem/viz/terrain_class.hpp"

namespace erodem::io {
class ResultReader;
}

namespace erodem::viz {

/// A field the viewer can colour the terrain by.
struct ViewField {
  std::string name;   ///< "bed", "water_depth", ..., or a derived "speed", "terrain_class"
  std::string units;  ///< UDUNITS ("m", "m s-1"), "1" for classes
  std::string long_name;
  ColorMap map = ColorMap::terrain;
  bool stored = true;  ///< stored in the file (false: derived by the viewer)
};

/// How to read a DEM that carries no georeferencing (as `[dem]` in a config).
struct DemOptions {
  double cell_size = 0.0;  ///< m; required for files without georeferencing
  double z_scale = 1.0;    ///< multiplier of the stored values (1)
  std::string crs;         ///< CRS for files without georeferencing ("" = none)
};

/// The values of every field at one cell and time.
struct CellValues {
  int col = 0, row = 0;                                ///< full-resolution cell
  double x = 0.0, y = 0.0;                             ///< its centre in the grid's CRS (CRS units)
  double time = 0.0;                                   ///< s
  std::vector<std::pair<std::string, double>> values;  ///< field name, value (NaN = nodata)
};

/// A result file (`.h5`, read with io::ResultReader) or a DEM (read with io::read_dem) as
/// the viewer sees it: the grid, the stored times and the fields, stored and derived:
/// - `speed` (m s-1) = hypot(velocity_x, velocity_y), when both are stored;
/// - `erosion` (m) = bed at the first snapshot - bed, when `erosion` is not stored but
///   `bed` is (negative = deposition);
/// - `terrain_class` (classify_terrain on the bed, wet by `wetness` or `water_depth`).
/// A DEM is one snapshot at t = 0 with the field `bed`.
///
/// Errors: a missing file -> Error(no_input, 66); a file that is neither a result file nor
/// a raster -> Error(data, 65); an unknown field or a time that is not stored ->
/// Error(data, 65) naming it and listing what is there.
class ViewData {
 public:
  /// Opens `path`: a result file when it starts with the HDF5 signature, else a DEM.
  explicit ViewData(const std::string& path, const DemOptions& dem = {});
  ~ViewData();
  ViewData(const ViewData&) = delete;
  ViewData& operator=(const ViewData&) = delete;

  const std::string& path() const { return path_; }
  bool is_result() const { return reader_ != nullptr; }
  const Grid& grid() const { return grid_; }
  /// Snapshot times (s); {0} for a DEM.
  const std::vector<double>& times() const { return times_; }
  /// The fields the terrain can be coloured by, stored first, then derived.
  const std::vector<ViewField>& fields() const { return fields_; }
  /// Whether `name` is one of fields().
  bool has_field(const std::string& name) const;
  /// The field `name`; unknown -> Error(data) listing the fields.
  const ViewField& field(const std::string& name) const;
  /// The index of stored time `time` (s), matched to 1e-9 relative; not stored ->
  /// Error(data) listing the stored times.
  std::size_t time_index(double time) const;
  /// The index of the snapshot nearest to `time` (s; the earlier one on a tie). A time
  /// further than the largest gap between snapshots before the first or after the last
  /// (a single snapshot: further than 1e-9 relative) -> Error(data) with the stored range.
  std::size_t nearest_time_index(double time) const;
  /// The index of snapshot `k`: 0-based, negative counts from the end (-1 = the last);
  /// out of range -> Error(usage) naming --snapshot and the range.
  std::size_t snapshot_index(long k) const;
  /// Field `name` at snapshot `index` (row-major, NaN = nodata), cached.
  const std::vector<float>& values(const std::string& name, std::size_t index);
  /// The bed (m) at snapshot `index`: the stored bed, else the DEM's or the first stored.
  const std::vector<float>& bed(std::size_t index);
  /// Whether the bed changes over time (stored in the result file).
  bool bed_varies() const;
  /// Every field's value at cell (col, row) and snapshot `index`.
  CellValues cell_values(int col, int row, std::size_t index);
  /// cell_values at every snapshot, in time order: the cell's time series, of the fields
  /// `names` (in that order; empty: every field). Reads each snapshot once, around the cache.
  std::vector<CellValues> cell_series(int col, int row, const std::vector<std::string>& names = {});
  /// The colour range of field `name` under `map` held over all snapshots: color_range of
  /// the values of all snapshots pooled, so the percentiles are the whole run's. Beyond 4 M
  /// values in all the percentiles are taken of every k-th cell; the minimum and maximum
  /// stay exact. Computed once per field and map, around the cache.
  std::array<double, 2> held_color_range(const std::string& name, ColorMap map);
  /// A one-line description: file, grid size, CRS kind, number of snapshots.
  std::string describe() const;
  /// The rule of the terrain classes.
  ClassRule class_rule;

 private:
  std::string path_;
  std::unique_ptr<io::ResultReader> reader_;
  Grid grid_;
  std::vector<double> times_;
  std::vector<std::string> stored_;
  std::vector<ViewField> fields_;
  std::vector<float> dem_bed_;
  std::map<std::pair<std::string, std::size_t>, std::vector<float>> cache_;
  std::vector<std::pair<std::string, std::size_t>> cache_order_;
  std::map<std::pair<std::string, ColorMap>, std::array<double, 2>> held_ranges_;
  bool stored(const std::string& name) const;
  std::vector<float> compute(const std::string& name, std::size_t index);
};

/// The list "a, b, c" of names, for error messages.
std::string join_names(const std::vector<std::string>& names);

}  // namespace erodem::viz
