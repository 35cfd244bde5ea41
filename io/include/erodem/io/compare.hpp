// erodem — comparing run outputs field by field (`erodem compare`, tests/test_agreement.cpp):
// the two sides, their fields read as rasters at one snapshot time, the check that both lie on
// one grid, the difference of one field at one time (relative L2 and largest absolute
// difference), and the snapshot times two outputs share.
//
// A run output is a result file (`run.h5`, read with io::ResultReader), the set of GeoTIFFs
// that `erodem run` wrote before the HDF5 writer (`out.h5` -> out_bed.tif, ...), or a single
// GeoTIFF. A GeoTIFF holds one state: it is compared with the last snapshot of a result file.
#pragma once

#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "erodem/io/results.hpp"

namespace erodem::io {

/// One side of the comparison: a result file, or field name -> GeoTIFF. A single GeoTIFF
/// has one entry, named after the field its file name ends with ("out_water_depth.tif"),
/// else "".
struct CompareInput {
  std::string path;
  bool single = false;
  std::shared_ptr<ResultReader> h5;  ///< set for a result file
  std::map<std::string, std::string> files;

  /// Whether this side holds `field`.
  bool has(const std::string& field) const;
  /// The fields it holds: a result file's in its order, GeoTIFFs' in field_table() order.
  std::vector<std::string> fields() const;
  /// The message for `field` missing here.
  std::string missing(const std::string& field) const;
};

/// One side from its path: a .tif/.tiff name is a single GeoTIFF (missing ->
/// Error(no_input)); an existing file is a result file (not one -> Error(data)); else the
/// GeoTIFFs `<path without extension>_<field>.tif` (none -> Error(no_input)).
CompareInput open_compare_input(const std::string& path);

/// Band 1 of a raster, nodata and non-finite values as NaN, with its georeferencing.
struct RasterBand {
  std::string path;
  int nx = 0, ny = 0;
  bool has_transform = false;
  double transform[6] = {0, 1, 0, 0, 0, 1};
  std::string crs_wkt;
  std::vector<double> values;
};

/// Band 1 of a raster file (any GDAL reads), with the band's scale and offset applied.
/// Missing -> Error(no_input); not a raster, or without a band -> Error(data); reading
/// failed -> Error(io).
RasterBand read_raster_band(const std::string& path);

/// Field `field` of a result file at snapshot `index`, as a RasterBand.
RasterBand read_snapshot_band(const ResultReader& r, const std::string& field, std::size_t index);

/// Both rasters on one grid: size, geotransform (within 1e-6 of a cell) and CRS; else
/// Error(data) naming both files and what differs.
void check_same_grid(const RasterBand& a, const RasterBand& b);

/// One field compared at one time.
struct FieldDifference {
  std::size_t cells = 0;           ///< cells valid in both
  std::size_t valid_mismatch = 0;  ///< cells valid (not NaN) in one and nodata in the other
  double rel_l2 = 0.0;             ///< ||a - b|| / ||b||; 0 when both are 0, inf when only b is
  double max_abs = 0.0;
  int max_col = -1, max_row = -1;  ///< -1: no difference
};

/// The difference of `a` from the reference `b`, two fields of the same size on a grid `nx`
/// cells wide (row-major): over the cells valid (not NaN) in both, ||a - b|| / ||b|| and the
/// largest |a - b| with its cell; the cells valid in one only are counted.
FieldDifference field_difference(const std::vector<double>& a, const std::vector<double>& b,
                                 int nx);

/// A snapshot of each side to compare; index -1 is a GeoTIFF's one state.
struct TimePair {
  double time = std::nan("");  ///< s; NaN when neither side is a result file
  long ia = -1, ib = -1;
};

/// Result file against result file: every snapshot time both hold (to 1e-9 relative);
/// none -> Error(data). A result file against GeoTIFFs: its last snapshot.
std::vector<TimePair> matching_times(const CompareInput& a, const CompareInput& b);

/// Field `field` of one side at snapshot `index` of a result file (-1: a GeoTIFF's state).
RasterBand load_compare_field(const CompareInput& o, const std::string& field, long index);

}  // namespace erodem::io
