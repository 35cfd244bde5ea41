// erodem — GeoTIFF output (raster.hpp): write_geotiff(), through a temporary file renamed
// into place.
#include <cpl_error.h>
#include <gdal.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <system_error>

#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {

namespace fs = std::filesystem;

void write_geotiff(const std::string& path, const Grid& grid, const std::vector<float>& values,
                   const std::string& description, double nodata) {
  write_geotiff_bands(path, grid, {values}, description, nodata);
}

void write_geotiff_bands(const std::string& path, const Grid& grid,
                         const std::vector<std::vector<float>>& bands,
                         const std::string& description, double nodata) {
  ensure_gdal();
  QuietGdal quiet;
  for (const auto& values : bands)
    if (grid.nx < 1 || grid.ny < 1 || values.size() != grid.cells())
      throw Error(ExitCode::internal, path + ": " + std::to_string(values.size()) +
                                          " values for a " + size_text(grid.nx, grid.ny) + " grid");
  if (bands.empty()) throw Error(ExitCode::internal, path + ": no band to write");
  const fs::path target(path);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(ExitCode::cant_create,
                path + ": cannot create: directory " + dir.string() + " does not exist");

  static std::atomic<unsigned long> counter{0};
  const auto stamp =
      static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp-" + std::to_string(stamp) +
                              "-" + std::to_string(counter++) + ".tif");
  const std::string tmp_s = tmp.string();

  /// Removes the temporary file (and any sidecar GDAL wrote) unless committed. Declared
  /// before the dataset so that the dataset is closed first.
  struct TempGuard {
    std::string file;
    bool committed = false;
    ~TempGuard() {
      if (committed) return;
      std::error_code e;
      fs::remove(file, e);
      fs::remove(file + ".aux.xml", e);
    }
  } guard{tmp_s};

  GDALDriverH drv = GDALGetDriverByName("GTiff");
  if (drv == nullptr) throw Error(ExitCode::internal, "GDAL has no GTiff driver");
  const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=3", "TILED=YES", "BIGTIFF=IF_SAFER",
                           nullptr};
  CPLErrorReset();
  Dataset ds(GDALCreate(drv, tmp_s.c_str(), grid.nx, grid.ny, static_cast<int>(bands.size()),
                        GDT_Float32, const_cast<char**>(options)));
  if (!ds) throw Error(ExitCode::cant_create, path + ": cannot create" + gdal_reason());
  GDALDatasetH h = ds.get();

  std::array<double, 6> gt = grid.georef.transform;
  bool ok = GDALSetGeoTransform(h, gt.data()) == CE_None;
  if (!grid.georef.crs_wkt.empty())
    ok = ok && GDALSetProjection(h, grid.georef.crs_wkt.c_str()) == CE_None;
  else
    ok = ok && GDALSetMetadataItem(h, kUnitsKey, "metre", nullptr) == CE_None;
  if (!description.empty())
    ok = ok && GDALSetMetadataItem(h, "TIFFTAG_IMAGEDESCRIPTION", description.c_str(), nullptr) ==
                   CE_None;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    GDALRasterBandH band = GDALGetRasterBand(h, static_cast<int>(b) + 1);
    if (!description.empty()) GDALSetDescription(band, description.c_str());
    ok = ok && GDALSetRasterNoDataValue(band, nodata) == CE_None;
    if (!ok) throw Error(ExitCode::io, path + ": cannot write georeferencing" + gdal_reason());
    if (GDALRasterIO(band, GF_Write, 0, 0, grid.nx, grid.ny, const_cast<float*>(bands[b].data()),
                     grid.nx, grid.ny, GDT_Float32, 0, 0) != CE_None)
      throw Error(ExitCode::io, path + ": write failed" + gdal_reason());
  }
  CPLErrorReset();
  GDALFlushCache(h);
  ds.reset();  // GDAL 3.6's GDALClose returns nothing: check the error state instead
  if (CPLGetLastErrorType() == CE_Failure || CPLGetLastErrorType() == CE_Fatal)
    throw Error(ExitCode::io, path + ": write failed" + gdal_reason());

  fs::rename(tmp, target, ec);
  if (ec)
    throw Error(ExitCode::cant_create,
                path + ": cannot move the finished file into place: " + ec.message());
  guard.committed = true;
  std::error_code ignore;
  fs::remove(tmp_s + ".aux.xml", ignore);
}

}  // namespace erodem::io
