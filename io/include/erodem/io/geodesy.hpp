// erodem — cell sizes and areas of geographic (lat/lon) grids on an ellipsoid, through
// GeographicLib (geodesics) and the closed-form area of a latitude-longitude quadrangle.
#pragma once

#include <string>

#include "erodem/grid.hpp"

namespace erodem::io {

/// An ellipsoid of revolution, as a geographic CRS names it.
struct Ellipsoid {
  double semi_major = 6378137.0;              ///< a, equatorial radius (m)
  double inverse_flattening = 298.257223563;  ///< 1/f; 0 means a sphere (f = 0)
  std::string name = "WGS 84";

  /// f = 1 / inverse_flattening, 0 for a sphere.
  double flattening() const { return inverse_flattening == 0.0 ? 0.0 : 1.0 / inverse_flattening; }
  static Ellipsoid wgs84() { return {}; }
  static Ellipsoid grs80() { return {6378137.0, 298.257222101, "GRS 1980"}; }
  /// Throws Error(ExitCode::data) naming `what` unless a > 0 is finite and 1/f is 0 (a
  /// sphere) or a finite oblate flattening (1/f > 1).
  void validate(const std::string& what) const;
};

/// Area (m^2) of the ellipsoidal quadrangle between latitudes `lat1` and `lat2` (degrees,
/// either order, within [-90, 90]) and `dlon` degrees of longitude (its sign is ignored):
/// `|dlon| * b^2 * [G(sin lat2) - G(sin lat1)]` with
/// `G(x) = x / (2 (1 - e^2 x^2)) + atanh(e x) / (2 e)` (the area of the zone from the equator,
/// divided by 2 pi), the difference written so that it keeps full relative precision for
/// cells of a fraction of an arc second.
double quadrangle_area(const Ellipsoid& e, double lat1, double lat2, double dlon);

/// Fills `grid.dx`, `grid.dy` and `grid.area` (one value per row; all cells of a row have
/// the same size) for a north-up lat/lon grid of `grid.ny` rows whose row r spans latitudes
/// `lat0 + r * dlat` .. `lat0 + (r + 1) * dlat` (degrees; `dlat` is the geotransform's
/// pixel height, negative for north-up) and whose cells are `dlon` degrees wide:
/// - dx(r): geodesic distance (GeographicLib::Geodesic::Inverse) between the centres of two
///   adjacent cells of row r, on the row's centre latitude;
/// - dy(r): length of the meridian arc from the row's north edge to its south edge (the
///   kernels take 0.5 (dy(r) + dy(r+1)) as the distance between row centres);
/// - area(r): quadrangle_area() of one cell, exact on the ellipsoid.
///
/// Throws Error(ExitCode::data) naming `what` when a latitude is outside [-90, 90] (beyond
/// rounding), when `dlat` or `dlon` is zero or not finite, or when a cell is 180 degrees
/// wide or more.
void set_geographic_rows(Grid& grid, const Ellipsoid& e, double lat0, double dlat, double dlon,
                         const std::string& what);

}  // namespace erodem::io
