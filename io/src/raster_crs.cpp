// erodem — CRS helpers of raster files (raster_gdal.hpp): user CRSs, units, ellipsoids, the
// cell sizes of geographic grids; and describe_crs() (raster.hpp).
#include <cpl_conv.h>
#include <cpl_error.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <memory>

#include "erodem/error.hpp"
#include "erodem/io/geodesy.hpp"
#include "erodem/io/raster.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {
namespace {

struct CplFree {
  void operator()(char* p) const { CPLFree(p); }
};

/// WKT (WKT1, as GDAL writes into GeoTIFFs) of a spatial reference; `what` names it in
/// errors.
std::string wkt_of(OGRSpatialReferenceH h, const std::string& what) {
  char* wkt = nullptr;
  if (OSRExportToWkt(h, &wkt) != OGRERR_NONE || wkt == nullptr) {
    CPLFree(wkt);
    throw config_error("dem.crs", "'" + what + "' cannot be written as WKT");
  }
  std::unique_ptr<char, CplFree> owned(wkt);
  return std::string(wkt);
}

/// Degrees per angular unit of a geographic CRS (1 for degrees, snapped so that the WKT's
/// rounded radian value of a degree does not scale every coordinate by 1 + 3e-16).
double degrees_per_unit(OGRSpatialReferenceH h) {
  const double radians = OSRGetAngularUnits(h, nullptr);
  const double degrees = radians * 180.0 / 3.14159265358979323846;
  return std::fabs(degrees - 1.0) < 1e-12 ? 1.0 : degrees;
}

/// The ellipsoid of a geographic (or projected) CRS; `what` names the source in errors.
Ellipsoid ellipsoid_of(OGRSpatialReferenceH h, const std::string& what) {
  OGRErr err_a = OGRERR_NONE, err_f = OGRERR_NONE;
  Ellipsoid e;
  e.semi_major = OSRGetSemiMajor(h, &err_a);
  e.inverse_flattening = OSRGetInvFlattening(h, &err_f);
  const char* name = OSRGetAttrValue(h, "SPHEROID", 0);
  e.name = name != nullptr ? name : "";
  if (err_a != OGRERR_NONE || err_f != OGRERR_NONE)
    throw Error(ExitCode::data, what + ": its CRS names no ellipsoid");
  e.validate(what);
  return e;
}

}  // namespace

std::string user_crs_wkt(const std::string& crs, double& metres_per_unit, bool& geographic) {
  Srs srs(OSRNewSpatialReference(nullptr));
  CPLErrorReset();
  auto h = static_cast<OGRSpatialReferenceH>(srs.get());
  if (OSRSetFromUserInput(h, crs.c_str()) != OGRERR_NONE)
    throw config_error("dem.crs", "'" + crs + "' is not a CRS GDAL recognises" + gdal_reason());
  geographic = OSRIsGeographic(h) != 0;
  if (!geographic && OSRIsProjected(h) == 0 && OSRIsLocal(h) == 0)
    throw config_error("dem.crs", "'" + crs +
                                      "' is neither a projected nor a geographic (lat/lon) CRS "
                                      "(a geocentric or vertical CRS cannot place a raster)");
  metres_per_unit = geographic ? 1.0 : OSRGetLinearUnits(h, nullptr);
  return wkt_of(h, crs);
}

void set_geographic_grid(Grid& g, OGRSpatialReferenceH h, const std::array<double, 6>& gt,
                         const std::string& what) {
  if (gt[2] != 0.0 || gt[4] != 0.0)
    throw Error(ExitCode::data, what + ": rotated geotransforms are not supported");
  const double deg = degrees_per_unit(h);
  set_geographic_rows(g, ellipsoid_of(h, what), gt[3] * deg, gt[5] * deg, gt[1] * deg, what);
}

Srs parse_srs(const std::string& text) {
  Srs srs(OSRNewSpatialReference(nullptr));
  if (OSRSetFromUserInput(static_cast<OGRSpatialReferenceH>(srs.get()), text.c_str()) !=
      OGRERR_NONE)
    return Srs();
  return srs;
}

CrsInfo describe_crs(const std::string& crs) {
  ensure_gdal();
  QuietGdal quiet;
  if (crs.empty()) throw Error(ExitCode::data, "no CRS to describe");
  Srs srs = parse_srs(crs);
  if (!srs) throw Error(ExitCode::data, "not a CRS GDAL recognises" + gdal_reason());
  auto h = static_cast<OGRSpatialReferenceH>(srs.get());
  CrsInfo info;
  const char* name = OSRGetName(h);
  info.name = name != nullptr ? name : "";
  const char* auth = OSRGetAuthorityName(h, nullptr);
  const char* code = OSRGetAuthorityCode(h, nullptr);
  if (auth != nullptr && code != nullptr) {
    info.authority = std::string(auth) + ":" + code;
  } else {
    // A CRS written without its code (e.g. NAD83 in a GeoTIFF's keys): the code of the one
    // CRS of the database that matches it with full confidence, if any.
    int n = 0;
    int* confidence = nullptr;
    OGRSpatialReferenceH* matches = OSRFindMatches(h, nullptr, &n, &confidence);
    if (matches != nullptr && n >= 1 && confidence[0] == 100 && (n == 1 || confidence[1] < 100)) {
      auth = OSRGetAuthorityName(matches[0], nullptr);
      code = OSRGetAuthorityCode(matches[0], nullptr);
      if (auth != nullptr && code != nullptr) info.authority = std::string(auth) + ":" + code;
    }
    OSRFreeSRSArray(matches);
    CPLFree(confidence);
  }
  info.wkt = wkt_of(h, crs);
  info.geographic = OSRIsGeographic(h) != 0;
  info.projected = OSRIsProjected(h) != 0;
  char* unit = nullptr;
  if (info.geographic) {
    OSRGetAngularUnits(h, &unit);
    info.unit_factor = degrees_per_unit(h);
  } else {
    info.unit_factor = OSRGetLinearUnits(h, &unit);
  }
  info.unit = unit != nullptr ? unit : "";  // owned by the spatial reference
  OGRErr err_a = OGRERR_NONE, err_f = OGRERR_NONE;
  info.ellipsoid.semi_major = OSRGetSemiMajor(h, &err_a);
  info.ellipsoid.inverse_flattening = OSRGetInvFlattening(h, &err_f);
  const char* ell = OSRGetAttrValue(h, "SPHEROID", 0);
  info.ellipsoid.name = ell != nullptr ? ell : "";
  if (err_a != OGRERR_NONE || err_f != OGRERR_NONE) {
    info.ellipsoid.semi_major = std::nan("");
    info.ellipsoid.inverse_flattening = std::nan("");
  }
  return info;
}

}  // namespace erodem::io
