// `erodem info DEM` (a result file: info_result.cpp): what a DEM holds and how erodem reads it —
// size, cell size in metres, CRS (geographic or projected, with its ellipsoid), extent, elevations,
// nodata, area, checksum. A file without georeferencing is described as far as it goes, with the
// config keys it needs; that is not an error (exit 0).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/grid.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/params.hpp"
#include "erodem/units.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace {

struct InfoOptions {
  std::string path, cell_size, crs;
  double z_scale = 1.0;
  bool json = false;
};

/// Everything `info` reports, gathered before printing.
struct DemInfo {
  io::RasterHeader header;
  Terrain terrain;
  bool georeferenced = false;      ///< cell sizes are known (from the file or the options)
  std::optional<io::CrsInfo> crs;  ///< the CRS in use, when there is one
  std::vector<std::string> needs;  ///< config keys a run needs for this file
  std::string hint;                ///< a remark on what those keys might be
  std::string options_crs;         ///< --crs, when given
  double dx_min = 0, dx_max = 0, dy_min = 0, dy_max = 0;
  double z_min = 0, z_max = 0, z_mean = 0;
  std::size_t valid = 0;
  double area_total = 0, area_valid = 0;  ///< m^2
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

/// A JSON number with up to 15 significant digits (coordinates need more than 7).
std::string jnum(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt("%.15g", v);
}

DemInfo gather(const InfoOptions& o) {
  DemInfo info;
  info.options_crs = o.crs;
  info.header = io::read_raster_header(o.path);
  const io::RasterHeader& h = info.header;
  const bool file_georef = h.has_transform && (!h.crs_wkt.empty() || h.erodem_metres);

  Params::Dem dem;
  dem.path = o.path;
  dem.z_scale = o.z_scale;
  dem.crs = o.crs;
  if (!o.cell_size.empty())
    dem.cell_size = parse_quantity(o.cell_size, Dimension::length, "dem.cell_size", "--cell-size");
  info.georeferenced = file_georef || dem.cell_size > 0.0 || (h.has_transform && !o.crs.empty());
  if (!info.georeferenced) {
    // Read the values on a placeholder 1 m grid; no cell size is reported.
    dem.cell_size = 1.0;
    if (h.has_transform) {
      info.needs = {"dem.crs", "dem.cell_size"};
      const double px = std::fabs(h.transform[1]), py = std::fabs(h.transform[5]);
      const double x0 = h.transform[0], y0 = h.transform[3];
      const double x1 = x0 + h.nx * h.transform[1], y1 = y0 + h.ny * h.transform[5];
      const bool degrees_like = px < 1.0 && py < 1.0 && std::fabs(x0) <= 360.0 &&
                                std::fabs(x1) <= 360.0 && std::fabs(y0) <= 90.0 &&
                                std::fabs(y1) <= 90.0;
      info.hint = "it has a geotransform (pixel " + fmt("%.9g", px) + " x " + fmt("%.9g", py) +
                  ") but no CRS: set dem.crs to the CRS those coordinates are in" +
                  (degrees_like ? " (they look like degrees of longitude and latitude: "
                                  "dem.crs = \"EPSG:4326\" if they are WGS84)"
                                : "") +
                  ", or dem.cell_size (m) to ignore them";
    } else {
      info.needs = {"dem.cell_size", "dem.crs"};
      info.hint =
          "it has no geotransform: set dem.cell_size (m), and dem.crs (a projected CRS) to "
          "place it on a map";
    }
  }
  info.terrain = io::read_dem(dem);
  const Terrain& t = info.terrain;
  const Grid& g = t.grid;
  if (!g.georef.crs_wkt.empty()) info.crs = io::describe_crs(g.georef.crs_wkt);

  info.dx_min = *std::min_element(g.dx.begin(), g.dx.end());
  info.dx_max = *std::max_element(g.dx.begin(), g.dx.end());
  info.dy_min = *std::min_element(g.dy.begin(), g.dy.end());
  info.dy_max = *std::max_element(g.dy.begin(), g.dy.end());
  info.z_min = std::numeric_limits<double>::infinity();
  info.z_max = -info.z_min;
  double sum = 0;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * g.nx + c;
      const double a = g.area[static_cast<std::size_t>(r)];
      info.area_total += a;
      if (!t.active(i)) continue;
      ++info.valid;
      info.area_valid += a;
      info.z_min = std::min(info.z_min, t.bed[i]);
      info.z_max = std::max(info.z_max, t.bed[i]);
      sum += t.bed[i];
    }
  info.z_mean = sum / static_cast<double>(info.valid);  // read_dem guarantees one valid cell
  return info;
}

/// The extent of the grid in its CRS units: west, east, south, north.
std::array<double, 4> extent(const Grid& g) {
  const auto& t = g.georef.transform;
  const double xa = t[0], xb = t[0] + g.nx * t[1];
  const double ya = t[3], yb = t[3] + g.ny * t[5];
  return {std::min(xa, xb), std::max(xa, xb), std::min(ya, yb), std::max(ya, yb)};
}

std::string kind_of(const DemInfo& d) {
  if (!d.georeferenced) return "none";
  if (d.terrain.grid.georef.is_geographic) return "geographic";
  return d.crs ? "projected" : "local";
}

std::string crs_text(const DemInfo& d) {
  if (!d.crs) {
    if (!d.georeferenced) return "none";
    return d.header.erodem_metres ? "none (local coordinates in metres, written by erodem)"
                                  : "none (local coordinates in metres)";
  }
  std::string s = d.crs->name.empty() ? "(unnamed)" : d.crs->name;
  if (!d.crs->authority.empty()) s += " (" + d.crs->authority + ")";
  s += d.crs->geographic ? ", geographic (lat/lon)" : d.crs->projected ? ", projected" : ", local";
  if (!d.options_crs.empty()) s += ", from --crs";
  return s;
}

void print_text(const InfoOptions& o, const DemInfo& d) {
  const Grid& g = d.terrain.grid;
  const io::RasterHeader& h = d.header;
  std::printf("DEM        %s\n", o.path.c_str());
  std::string nodata = h.nodata ? ", nodata value " + fmt("%.9g", *h.nodata) : ", no nodata value";
  std::printf("format     %s (%s), %s, %d band%s%s\n", h.driver.c_str(), h.driver_long.c_str(),
              h.data_type.c_str(), h.bands, h.bands == 1 ? "" : "s", nodata.c_str());
  std::printf("size       %d x %d cells (%zu)\n", g.nx, g.ny, g.cells());
  std::printf("CRS        %s\n", crs_text(d).c_str());
  if (d.crs && d.crs->geographic) {
    const auto& e = d.crs->ellipsoid;
    std::printf("ellipsoid  %s (a = %.3f m, 1/f = %.9f)\n", e.name.c_str(), e.semi_major,
                e.inverse_flattening);
  }
  if (!d.georeferenced) {
    std::printf("cell size  unknown: %s has no georeferencing\n", o.path.c_str());
    std::printf("needs      %s or %s in a config (--crs / --cell-size here): %s\n",
                d.needs[0].c_str(), d.needs[1].c_str(), d.hint.c_str());
  } else if (g.georef.is_geographic) {
    std::printf(
        "cell size  dx %.4f .. %.4f m (by row: %.4f m at the north edge, %.4f m at the "
        "south edge), dy %.4f .. %.4f m; geodesic on the ellipsoid\n",
        d.dx_min, d.dx_max, g.dx.front(), g.dx.back(), d.dy_min, d.dy_max);
  } else {
    std::printf("cell size  dx %.6g m, dy %.6g m\n", d.dx_min, d.dy_min);
  }
  if (d.georeferenced && g.georef.has_transform) {
    const auto ex = extent(g);
    if (g.georef.is_geographic)
      std::printf("extent     lon %.9g .. %.9g, lat %.9g .. %.9g (%s)\n", ex[0], ex[1], ex[2],
                  ex[3], d.crs->unit.c_str());
    else
      std::printf("extent     x %.10g .. %.10g, y %.10g .. %.10g (%s)\n", ex[0], ex[1], ex[2],
                  ex[3], d.crs ? d.crs->unit.c_str() : "metre");
  }
  const double zs = o.z_scale;
  std::printf("elevation  %.6g .. %.6g m, mean %.6g m (valid cells%s)\n", d.z_min, d.z_max,
              d.z_mean, zs != 1.0 ? (", z_scale " + fmt("%g", zs)).c_str() : "");
  const double frac = 1.0 - static_cast<double>(d.valid) / static_cast<double>(g.cells());
  std::printf("nodata     %.4f %% (%zu of %zu cells)\n", 100.0 * frac, g.cells() - d.valid,
              g.cells());
  if (d.georeferenced)
    std::printf("area       %.6g km^2 in all, %.6g km^2 of valid cells\n", d.area_total * 1e-6,
                d.area_valid * 1e-6);
  std::printf("sha256     %s\n", d.terrain.source_sha256.c_str());
}

void print_json(const InfoOptions& o, const DemInfo& d) {
  const Grid& g = d.terrain.grid;
  const io::RasterHeader& h = d.header;
  std::string s = "{\n";
  auto field = [&s](const std::string& key, const std::string& value, bool last = false) {
    s += "  " + json_string(key) + ": " + value + (last ? "\n" : ",\n");
  };
  field("path", json_string(o.path));
  field("driver", json_string(h.driver));
  field("driver_long", json_string(h.driver_long));
  field("data_type", json_string(h.data_type));
  field("bands", std::to_string(h.bands));
  field("nodata_value", h.nodata ? jnum(*h.nodata) : "null");
  field("nx", std::to_string(g.nx));
  field("ny", std::to_string(g.ny));
  field("georeferenced", d.georeferenced ? "true" : "false");
  field("kind", json_string(kind_of(d)));
  field("geographic", g.georef.is_geographic ? "true" : "false");
  if (d.crs) {
    const auto& c = *d.crs;
    std::string v = "{\"name\": " + json_string(c.name) + ", \"authority\": " +
                    (c.authority.empty() ? "null" : json_string(c.authority)) +
                    ", \"geographic\": " + (c.geographic ? "true" : "false") +
                    ", \"projected\": " + (c.projected ? "true" : "false") +
                    ", \"unit\": " + json_string(c.unit) +
                    ", \"from_option\": " + (d.options_crs.empty() ? "false" : "true") +
                    ", \"ellipsoid\": {\"name\": " + json_string(c.ellipsoid.name) +
                    ", \"semi_major_m\": " + jnum(c.ellipsoid.semi_major) +
                    ", \"inverse_flattening\": " + jnum(c.ellipsoid.inverse_flattening) + "}}";
    field("crs", v);
  } else {
    field("crs", "null");
  }
  if (d.georeferenced) {
    field("cell_size_m",
          "{\"dx_min\": " + jnum(d.dx_min) + ", \"dx_max\": " + jnum(d.dx_max) +
              ", \"dx_north\": " + jnum(g.dx.front()) + ", \"dx_south\": " + jnum(g.dx.back()) +
              ", \"dy_min\": " + jnum(d.dy_min) + ", \"dy_max\": " + jnum(d.dy_max) + "}");
  } else {
    field("cell_size_m", "null");
  }
  if (d.georeferenced && g.georef.has_transform) {
    const auto ex = extent(g);
    const std::string unit = d.crs ? d.crs->unit : "metre";
    field("extent", "{\"west\": " + jnum(ex[0]) + ", \"east\": " + jnum(ex[1]) +
                        ", \"south\": " + jnum(ex[2]) + ", \"north\": " + jnum(ex[3]) +
                        ", \"unit\": " + json_string(unit) + "}");
  } else {
    field("extent", "null");
  }
  field("elevation_m", "{\"min\": " + jnum(d.z_min) + ", \"max\": " + jnum(d.z_max) +
                           ", \"mean\": " + jnum(d.z_mean) + ", \"z_scale\": " + jnum(o.z_scale) +
                           "}");
  field("valid_cells", std::to_string(d.valid));
  field("nodata_fraction",
        jnum(1.0 - static_cast<double>(d.valid) / static_cast<double>(g.cells())));
  field("area_km2", d.georeferenced ? "{\"total\": " + jnum(d.area_total * 1e-6) +
                                          ", \"valid\": " + jnum(d.area_valid * 1e-6) + "}"
                                    : std::string("null"));
  std::string needs = "[";
  for (std::size_t i = 0; i < d.needs.size(); ++i)
    needs += (i ? ", " : "") + json_string(d.needs[i]);
  field("needs", needs + "]");
  field("hint", d.hint.empty() ? "null" : json_string(d.hint));
  field("sha256", json_string(d.terrain.source_sha256), true);
  s += "}\n";
  std::fputs(s.c_str(), stdout);
}

int info(const InfoOptions& o) {
  if (is_hdf5_file(o.path)) return info_result(o.path, o.json);
  const DemInfo d = gather(o);
  if (o.json)
    print_json(o, d);
  else
    print_text(o, d);
  return 0;
}

}  // namespace

Action add_info(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  auto* sub = app.add_subcommand(
      "info",
      "Describe a DEM (size, cell size, CRS, elevations) or a result file (fields, times, "
      "restart state, the run's books)");
  sub->add_option("file", o->path, "DEM file (any raster GDAL reads) or result file (.h5)")
      ->required();
  sub->add_flag("--json", o->json, "Print JSON instead of text");
  sub->add_option("--cell-size", o->cell_size,
                  "Cell size for a file without georeferencing (m, or \"160 m\")");
  sub->add_option("--crs", o->crs, "CRS for a file without one (\"EPSG:4326\", WKT, PROJ)");
  sub->add_option("--z-scale", o->z_scale, "Multiplier of the stored values (e.g. 0.1)");
  return [o] { return info(*o); };
}

}  // namespace erodem::cli
