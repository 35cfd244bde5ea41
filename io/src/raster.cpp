// erodem — raster input through GDAL (raster.hpp): GDAL set-up and errors, opening a
// raster, its pixel window, band 1 with its nodata (raster_gdal.hpp), a raster's header, and
// parameter rasters on the DEM's grid. The DEM itself: raster_dem.cpp; coarsening:
// raster_coarsen.cpp; CRS: raster_crs.cpp; GeoTIFF output: raster_geotiff.cpp; SHA-256:
// sha256.cpp.
#include "erodem/io/raster.hpp"

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <system_error>

#include "erodem/error.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {

namespace fs = std::filesystem;

// ---- GDAL set-up, handles and errors --------------------------------------------------

void ensure_gdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

std::string gdal_reason() {
  const char* msg = CPLGetLastErrorMsg();
  if (msg == nullptr || *msg == '\0') return "";
  return std::string(": ") + msg;
}

std::string window_text(const std::array<int, 4>& w) {
  return "[" + std::to_string(w[0]) + ", " + std::to_string(w[1]) + ", " + std::to_string(w[2]) +
         ", " + std::to_string(w[3]) + "]";
}

std::string size_text(int nx, int ny) {
  return std::to_string(nx) + " x " + std::to_string(ny);
}

// ---- opening a raster, its window and band 1 ------------------------------------------

namespace {

bool is_vsi(const std::string& path) {
  return path.rfind("/vsi", 0) == 0;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& v : items) out += (out.empty() ? "" : ", ") + v;
  return out;
}

}  // namespace

Dataset open_raster(const std::string& path, const std::string& prefix) {
  if (path.empty()) throw Error(ExitCode::config, prefix + "no file given");
  // a netCDF variable, NETCDF:"file.nc":var: its file must exist, its variable be one of it
  const auto nc = parse_netcdf_name(path);
  const std::string file = nc ? nc->file : path;
  if (!is_vsi(file)) {
    std::error_code ec;
    if (!fs::exists(file, ec)) throw Error(ExitCode::no_input, prefix + file + ": no such file");
  }
  CPLErrorReset();
  Dataset ds(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                        nullptr, nullptr, nullptr));
  if (!ds && nc) {
    const auto vars = netcdf_variables(nc->file);
    if (!vars.empty())
      throw Error(ExitCode::data, prefix + path + ": " + nc->file + " has no variable '" +
                                      nc->variable + "'; its variables: " + join(vars));
  }
  if (!ds)
    throw Error(ExitCode::data, prefix + path + ": not a raster GDAL can read" + gdal_reason());
  if (GDALGetRasterCount(ds.get()) < 1) {
    const auto vars = subdataset_variables(ds.get());
    if (!vars.empty())
      throw Error(ExitCode::data, prefix + path + ": holds several variables (" + join(vars) +
                                      "): name one as NETCDF:\"" + path + "\":" + vars.front());
    throw Error(ExitCode::data, prefix + path + ": has no raster band");
  }
  return ds;
}

std::array<int, 4> checked_window(GDALDatasetH ds, const std::optional<std::array<int, 4>>& window,
                                  const std::string& prefix, const std::string& path) {
  const int xs = GDALGetRasterXSize(ds), ys = GDALGetRasterYSize(ds);
  if (!window) return {0, 0, xs, ys};
  const auto& w = *window;
  const bool inside = w[0] >= 0 && w[1] >= 0 && w[2] >= 1 && w[3] >= 1 &&
                      static_cast<long long>(w[0]) + w[2] <= xs &&
                      static_cast<long long>(w[1]) + w[3] <= ys;
  if (!inside)
    throw Error(ExitCode::data, prefix + path + ": window " + window_text(w) +
                                    " (col, row, width, height) is not inside the raster (" +
                                    size_text(xs, ys) + ")");
  return w;
}

std::vector<double> read_band(GDALDatasetH ds, const std::array<int, 4>& w,
                              std::vector<std::uint8_t>& valid, const std::string& prefix,
                              const std::string& path, int band_index) {
  GDALRasterBandH band = GDALGetRasterBand(ds, band_index);
  const std::size_t n = static_cast<std::size_t>(w[2]) * static_cast<std::size_t>(w[3]);
  std::vector<double> v(n);
  CPLErrorReset();
  if (GDALRasterIO(band, GF_Read, w[0], w[1], w[2], w[3], v.data(), w[2], w[3], GDT_Float64, 0,
                   0) != CE_None)
    throw Error(ExitCode::data,
                prefix + path + ": cannot read band " + std::to_string(band_index) + gdal_reason());

  valid.assign(n, 1);
  const int flags = GDALGetMaskFlags(band);
  if ((flags & GMF_ALL_VALID) == 0) {
    // The mask band covers nodata values, per-dataset masks and alpha bands.
    GDALRasterBandH mask = GDALGetMaskBand(band);
    if (mask == nullptr || GDALRasterIO(mask, GF_Read, w[0], w[1], w[2], w[3], valid.data(), w[2],
                                        w[3], GDT_Byte, 0, 0) != CE_None)
      throw Error(ExitCode::data, prefix + path + ": cannot read the nodata mask" + gdal_reason());
  }
  int has_scale = 0, has_offset = 0;
  const double scale = GDALGetRasterScale(band, &has_scale);
  const double offset = GDALGetRasterOffset(band, &has_offset);
  const bool transform = (has_scale && scale != 1.0) || (has_offset && offset != 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (valid[i] != 0 && std::isfinite(v[i])) {
      valid[i] = 1;
      if (transform) v[i] = v[i] * (has_scale ? scale : 1.0) + (has_offset ? offset : 0.0);
    } else {
      valid[i] = 0;
      v[i] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  return v;
}

std::array<int, 4> rows_of_window(const std::array<int, 4>& w, std::array<int, 2> rows) {
  if (rows[1] < 0) return w;
  if (!(0 <= rows[0] && rows[0] < rows[1] && rows[1] <= w[3]))
    throw Error(ExitCode::internal, "rows [" + std::to_string(rows[0]) + ", " +
                                        std::to_string(rows[1]) + ") of a window of " +
                                        std::to_string(w[3]) + " rows");
  return {w[0], w[1] + rows[0], w[2], rows[1] - rows[0]};
}

std::array<double, 6> shifted(const std::array<double, 6>& t, int col, int row) {
  return {t[0] + col * t[1] + row * t[2], t[1], t[2], t[3] + col * t[4] + row * t[5], t[4], t[5]};
}

// ---- a raster's header, parameter rasters on a grid -----------------------------------

RasterHeader read_raster_header(const std::string& path) {
  ensure_gdal();
  QuietGdal quiet;
  Dataset ds = open_raster(path, "");
  GDALDatasetH h = ds.get();
  RasterHeader r;
  GDALDriverH drv = GDALGetDatasetDriver(h);
  if (drv != nullptr) {
    r.driver = GDALGetDriverShortName(drv);
    r.driver_long = GDALGetDriverLongName(drv);
  }
  r.nx = GDALGetRasterXSize(h);
  r.ny = GDALGetRasterYSize(h);
  r.bands = GDALGetRasterCount(h);
  GDALRasterBandH band = GDALGetRasterBand(h, 1);
  r.data_type = GDALGetDataTypeName(GDALGetRasterDataType(band));
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) r.nodata = nodata;
  r.has_transform = GDALGetGeoTransform(h, r.transform.data()) == CE_None;
  if (GDALGetSpatialRef(h) != nullptr) {
    const char* wkt = GDALGetProjectionRef(h);
    r.crs_wkt = wkt != nullptr ? wkt : "";
  }
  const char* units_tag = GDALGetMetadataItem(h, kUnitsKey, nullptr);
  r.erodem_metres = r.has_transform && r.crs_wkt.empty() && units_tag != nullptr &&
                    std::string(units_tag) == "metre";
  return r;
}

std::vector<std::vector<double>> read_raster_bands_on_grid(
    const std::string& path, const Grid& grid, const std::optional<std::array<int, 4>>& window,
    const std::string& what, bool all_bands, std::array<int, 2> rows) {
  ensure_gdal();
  QuietGdal quiet;
  const std::string prefix = what + ": ";
  Dataset ds = open_raster(path, prefix);
  GDALDatasetH h = ds.get();
  const std::array<int, 4> w = checked_window(h, window, prefix, path);
  if (w[2] != grid.nx || w[3] != grid.ny)
    throw Error(ExitCode::data, prefix + path + " is " + size_text(w[2], w[3]) +
                                    (window ? " (in window " + window_text(*window) + ")" : "") +
                                    " but the DEM grid is " + size_text(grid.nx, grid.ny));
  std::array<double, 6> gt{};
  if (grid.georef.has_transform && GDALGetGeoTransform(h, gt.data()) == CE_None) {
    const auto a = shifted(gt, w[0], w[1]);
    const auto& b = grid.georef.transform;
    const double tol = 1e-6 * std::max(std::fabs(b[1]), std::fabs(b[5]));
    bool same = true;
    for (int k = 0; k < 6; ++k) same = same && std::fabs(a[k] - b[k]) <= tol;
    if (!same) {
      std::ostringstream msg;
      msg.precision(12);
      msg << prefix << path << ": its geotransform (" << a[0] << ", " << a[1] << ", " << a[2]
          << ", " << a[3] << ", " << a[4] << ", " << a[5] << ") does not match the DEM grid's ("
          << b[0] << ", " << b[1] << ", " << b[2] << ", " << b[3] << ", " << b[4] << ", " << b[5]
          << ")";
      throw Error(ExitCode::data, msg.str());
    }
  }
  std::vector<std::uint8_t> valid;
  std::vector<std::vector<double>> bands;
  const int count = all_bands ? GDALGetRasterCount(h) : 1;
  const std::array<int, 4> read = rows_of_window(w, rows);
  for (int b = 1; b <= count; ++b) bands.push_back(read_band(h, read, valid, prefix, path, b));
  return bands;
}

std::vector<double> read_raster_on_grid(const std::string& path, const Grid& grid,
                                        const std::optional<std::array<int, 4>>& window,
                                        const std::string& what, std::array<int, 2> rows) {
  return std::move(read_raster_bands_on_grid(path, grid, window, what, false, rows).front());
}

}  // namespace erodem::io
