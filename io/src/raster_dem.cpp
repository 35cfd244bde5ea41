// erodem — read_dem() (raster.hpp): a DEM's window, georeferencing (projected, geographic
// or given by dem.cell_size / dem.crs), elevations with their nodata, checksum and
// resampling.
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <string>

#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {
namespace {

/// Sets constant per-row cell sizes dx, dy (m) and areas for all g.ny rows.
void set_uniform_rows(Grid& g, double dx, double dy) {
  g.dx.assign(static_cast<std::size_t>(g.ny), dx);
  g.dy.assign(static_cast<std::size_t>(g.ny), dy);
  g.area.assign(static_cast<std::size_t>(g.ny), dx * dy);
}

}  // namespace

Terrain read_dem(const Params::Dem& dem, std::array<int, 2> rows) {
  ensure_gdal();
  QuietGdal quiet;
  const std::string& path = dem.path;
  if (path.empty()) throw config_error("dem.path", "no DEM file given");
  if (!(std::isfinite(dem.z_scale) && dem.z_scale != 0.0))
    throw config_error("dem.z_scale", "must be a finite non-zero number");
  if (!(std::isfinite(dem.cell_size) && dem.cell_size >= 0.0))
    throw config_error("dem.cell_size", "must be a positive length (m)");

  Dataset ds = open_raster(path, "");
  GDALDatasetH h = ds.get();
  const std::array<int, 4> w = checked_window(h, dem.window, "", path);

  Terrain t;
  Grid& g = t.grid;

  // Georeferencing.
  std::array<double, 6> gt{};
  const bool has_gt = GDALGetGeoTransform(h, gt.data()) == CE_None;
  OGRSpatialReferenceH file_srs = GDALGetSpatialRef(h);  // owned by the dataset
  const char* units_tag = GDALGetMetadataItem(h, kUnitsKey, nullptr);
  const bool erodem_metres =
      has_gt && file_srs == nullptr && units_tag != nullptr && std::string(units_tag) == "metre";
  const bool georeferenced = has_gt && (file_srs != nullptr || erodem_metres);

  if (georeferenced) {
    if (dem.cell_size > 0.0)
      throw config_error("dem.cell_size", path +
                                              " has its own georeferencing; dem.cell_size is only "
                                              "for files without it");
    if (!dem.crs.empty())
      throw config_error("dem.crs", path +
                                        " has its own georeferencing; dem.crs is only for files "
                                        "without it");
    g.nx = w[2];
    g.ny = w[3];
    g.georef.transform = shifted(gt, w[0], w[1]);
    g.georef.has_transform = true;
    if (file_srs != nullptr) {
      const char* wkt = GDALGetProjectionRef(h);
      g.georef.crs_wkt = wkt != nullptr ? wkt : "";
    }
    if (file_srs != nullptr && OSRIsGeographic(file_srs)) {
      g.georef.is_geographic = true;
      set_geographic_grid(g, file_srs, g.georef.transform, path);
    } else {
      const double metres_per_unit =
          file_srs != nullptr ? OSRGetLinearUnits(file_srs, nullptr) : 1.0;
      if (gt[2] != 0.0 || gt[4] != 0.0)
        throw Error(ExitCode::data, path + ": rotated geotransforms are not supported");
      const double dx = std::fabs(gt[1]) * metres_per_unit;
      const double dy = std::fabs(gt[5]) * metres_per_unit;
      if (!(std::isfinite(dx) && dx > 0.0 && std::isfinite(dy) && dy > 0.0))
        throw Error(ExitCode::data, path + ": invalid pixel size in its geotransform");
      set_uniform_rows(g, dx, dy);
      g.georef.is_geographic = false;
    }
  } else if (dem.cell_size > 0.0) {
    g = Grid::uniform(w[2], w[3], dem.cell_size);
    g.georef.has_transform = false;
    if (!dem.crs.empty()) {
      double metres_per_unit = 1.0;
      bool geographic = false;
      g.georef.crs_wkt = user_crs_wkt(dem.crs, metres_per_unit, geographic);
      if (geographic)
        throw config_error("dem.crs", "'" + dem.crs + "' is geographic (lat/lon) but " + path +
                                          " has no geotransform to place its cells in degrees; "
                                          "dem.cell_size with dem.crs needs a projected CRS");
      // Grid::uniform's transform is in metres; express it in the CRS's unit.
      for (double* v : {&g.georef.transform[0], &g.georef.transform[1], &g.georef.transform[3],
                        &g.georef.transform[5]})
        *v /= metres_per_unit;
    }
  } else if (has_gt && !dem.crs.empty()) {
    double metres_per_unit = 1.0;
    bool geographic = false;
    g.georef.crs_wkt = user_crs_wkt(dem.crs, metres_per_unit, geographic);
    if (gt[2] != 0.0 || gt[4] != 0.0)
      throw Error(ExitCode::data, path + ": rotated geotransforms are not supported");
    g.nx = w[2];
    g.ny = w[3];
    g.georef.transform = shifted(gt, w[0], w[1]);
    g.georef.has_transform = true;
    if (geographic) {
      // The file's transform is taken as degrees (longitude, latitude) on this CRS.
      Srs srs = parse_srs(g.georef.crs_wkt);
      if (!srs) throw config_error("dem.crs", "'" + dem.crs + "' cannot be read back from WKT");
      g.georef.is_geographic = true;
      set_geographic_grid(g, static_cast<OGRSpatialReferenceH>(srs.get()), g.georef.transform,
                          path + " (with dem.crs = '" + dem.crs + "')");
    } else {
      set_uniform_rows(g, std::fabs(gt[1]) * metres_per_unit, std::fabs(gt[5]) * metres_per_unit);
    }
  } else {
    throw Error(ExitCode::config,
                path +
                    ": has no georeferencing; set dem.cell_size (and dem.crs), or dem.crs "
                    "alone when its geotransform is in that CRS's units");
  }
  g.validate();

  // Elevations (of the rows asked for).
  const bool some_rows = rows[1] >= 0;
  if (some_rows) {
    if (resample_factor(dem, g) > 1)
      throw Error(ExitCode::internal, path + ": a band of rows of a DEM to resample");
    t.row0 = rows[0];
    t.row1 = rows[1];
  }
  std::vector<std::uint8_t> valid;
  t.bed = read_band(h, rows_of_window(w, rows), valid, "", path);
  std::size_t n_valid = 0;
  for (std::size_t i = 0; i < t.bed.size(); ++i) {
    // dem.nodata_value marks cells of a file that declares no nodata (e.g. sea at 0).
    if (dem.nodata_value && t.bed[i] == *dem.nodata_value) valid[i] = 0;
    if (valid[i] != 0) {
      t.bed[i] *= dem.z_scale;
      ++n_valid;
    } else {
      t.bed[i] = std::nan("");
    }
  }
  ds.reset();
  t.source = path;
  if (some_rows) {  // whether any cell is valid, and the checksum, are load_terrain's
    t.mask = std::move(valid);
    return t;
  }
  if (n_valid == 0)
    throw Error(ExitCode::data, path + ": no valid (non-nodata) cells" +
                                    (dem.window ? " in window " + window_text(*dem.window) : ""));
  if (n_valid < t.bed.size()) t.mask = std::move(valid);
  t.source_sha256 = file_sha256(path);
  const int factor = resample_factor(dem, g);
  return factor > 1 ? coarsen(t, factor) : t;
}

}  // namespace erodem::io
