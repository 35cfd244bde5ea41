// erodem — the GDAL helpers of the raster files (private to io/src): GDAL set-up, its
// messages as erodem::Error text, owned handles, opening a raster, its pixel window, band 1
// with its nodata (raster.cpp), geotransforms, and the CRS helpers of DEM grids
// (raster_crs.cpp).
#pragma once

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "erodem/grid.hpp"

namespace erodem::io {

// ---- GDAL set-up, handles and errors --------------------------------------------------

/// Registers GDAL's drivers, once per process.
void ensure_gdal();

/// Silences GDAL's messages on this thread for its lifetime and resets the last error, so
/// that the last CPL error can become the erodem::Error message.
class QuietGdal {
 public:
  QuietGdal() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

/// ": <last GDAL message>" or "" when there is none.
std::string gdal_reason();

/// A GDAL dataset, closed on every path.
struct DatasetCloser {
  void operator()(void* ds) const {
    if (ds != nullptr) GDALClose(static_cast<GDALDatasetH>(ds));
  }
};
using Dataset = std::unique_ptr<void, DatasetCloser>;

/// A spatial reference, destroyed on every path.
struct SrsDestroyer {
  void operator()(void* srs) const {
    if (srs != nullptr) OSRDestroySpatialReference(static_cast<OGRSpatialReferenceH>(srs));
  }
};
using Srs = std::unique_ptr<void, SrsDestroyer>;

// ---- opening a raster, its window and band 1 (raster.cpp) -----------------------------

/// "[col, row, width, height]" of a pixel window.
std::string window_text(const std::array<int, 4>& w);

/// "nx x ny".
std::string size_text(int nx, int ny);

/// Opens a raster read-only; `prefix` starts every error message.
Dataset open_raster(const std::string& path, const std::string& prefix);

/// The variables of a netCDF file that GDAL lists as its subdatasets (none for a file of one
/// variable, which GDAL opens as that variable): of an open dataset, or of a file.
std::vector<std::string> subdataset_variables(GDALDatasetH ds);
std::vector<std::string> netcdf_variables(const std::string& file);

/// The rows [rows[0], rows[1]) of window `w` (col, row, width, height) as a window of their
/// own; `w` itself where rows[1] < 0. Error(internal) for rows outside it.
std::array<int, 4> rows_of_window(const std::array<int, 4>& w, std::array<int, 2> rows);

/// The pixel window to read: the whole raster, or `window` checked against it.
std::array<int, 4> checked_window(GDALDatasetH ds, const std::optional<std::array<int, 4>>& window,
                                  const std::string& prefix, const std::string& path);

/// Band `band_index` (1-based) of the window as double, with the band's scale and offset
/// applied; `valid` receives 1 for valid cells and 0 for nodata / masked / non-finite ones.
std::vector<double> read_band(GDALDatasetH ds, const std::array<int, 4>& w,
                              std::vector<std::uint8_t>& valid, const std::string& prefix,
                              const std::string& path, int band_index = 1);

/// The geotransform shifted to the top-left corner of pixel (col, row).
std::array<double, 6> shifted(const std::array<double, 6>& t, int col, int row);

/// The metadata item with which write_geotiff() tags a file without CRS whose transform is
/// in metres ("metre").
constexpr const char* kUnitsKey = "ERODEM_CRS_UNITS";

// ---- CRS helpers (raster_crs.cpp) -----------------------------------------------------

/// Parses a user CRS ("EPSG:32610", "EPSG:4326", WKT, PROJ string). Returns the WKT;
/// sets `geographic` and, for a projected (or local) CRS, `metres_per_unit`.
std::string user_crs_wkt(const std::string& crs, double& metres_per_unit, bool& geographic);

/// Cell sizes and areas of a lat/lon grid (g.nx, g.ny set) whose geotransform `gt` (already
/// shifted to the window) is in the angular unit of geographic CRS `h`.
void set_geographic_grid(Grid& g, OGRSpatialReferenceH h, const std::array<double, 6>& gt,
                         const std::string& what);

/// A spatial reference parsed from WKT (or any user input GDAL takes); null when it fails.
Srs parse_srs(const std::string& text);

}  // namespace erodem::io
