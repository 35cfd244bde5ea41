// erodem — cell sizes and areas of geographic grids. See geodesy.hpp.
#include "erodem/io/geodesy.hpp"

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <sstream>

#include "erodem/error.hpp"

namespace erodem::io {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;
/// Latitudes this far (degrees) beyond a pole are taken as rounding of the pole itself.
constexpr double kPoleSlack = 1e-9;

std::string number(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

}  // namespace

void Ellipsoid::validate(const std::string& what) const {
  const bool ok_a = std::isfinite(semi_major) && semi_major > 0.0;
  const bool ok_f =
      inverse_flattening == 0.0 || (std::isfinite(inverse_flattening) && inverse_flattening > 1.0);
  if (!(ok_a && ok_f))
    throw Error(ExitCode::data, what + ": unusable ellipsoid '" + name + "' (semi-major axis " +
                                    number(semi_major) + " m, inverse flattening " +
                                    number(inverse_flattening) + ")");
}

double quadrangle_area(const Ellipsoid& e, double lat1, double lat2, double dlon) {
  const double f = e.flattening();
  const double e2 = f * (2.0 - f);
  const double b2 = e.semi_major * e.semi_major * (1.0 - e2);
  const double p1 = lat1 * kDegree, p2 = lat2 * kDegree;
  const double x1 = std::sin(p1), x2 = std::sin(p2);
  // sin p2 - sin p1 without cancellation.
  const double dx = 2.0 * std::cos(0.5 * (p1 + p2)) * std::sin(0.5 * (p2 - p1));
  const double d1 = 1.0 - e2 * x1 * x1, d2 = 1.0 - e2 * x2 * x2;
  // x2 / (2 d2) - x1 / (2 d1) = (x2 - x1)(1 + e^2 x1 x2) / (2 d1 d2)
  const double t1 = dx * (1.0 + e2 * x1 * x2) / (2.0 * d1 * d2);
  // atanh(e x2) - atanh(e x1) = atanh(e (x2 - x1) / (1 - e^2 x1 x2))
  double t2 = 0.5 * dx;  // the sphere's limit
  if (e2 > 0.0) {
    const double ecc = std::sqrt(e2);
    t2 = std::atanh(ecc * dx / (1.0 - e2 * x1 * x2)) / (2.0 * ecc);
  }
  return std::fabs(dlon * kDegree * b2 * (t1 + t2));
}

void set_geographic_rows(Grid& grid, const Ellipsoid& e, double lat0, double dlat, double dlon,
                         const std::string& what) {
  e.validate(what);
  if (!(std::isfinite(lat0) && std::isfinite(dlat) && dlat != 0.0 && std::isfinite(dlon) &&
        dlon != 0.0))
    throw Error(ExitCode::data, what + ": invalid pixel size in its geotransform (" + number(dlon) +
                                    ", " + number(dlat) + " degrees)");
  const double width = std::fabs(dlon);
  if (width >= 180.0)
    throw Error(ExitCode::data,
                what + ": cells " + number(width) + " degrees wide are not supported");
  const int ny = grid.ny;
  auto edge = [&](int k) {
    const double lat = lat0 + k * dlat;
    if (!(std::fabs(lat) <= 90.0 + kPoleSlack))
      throw Error(ExitCode::data, what + ": row edge " + std::to_string(k) + " is at latitude " +
                                      number(lat) +
                                      ", outside [-90, 90]; is the CRS really geographic?");
    return std::fmax(-90.0, std::fmin(90.0, lat));
  };
  const GeographicLib::Geodesic geod(e.semi_major, e.flattening());
  grid.dx.assign(static_cast<std::size_t>(ny), 0.0);
  grid.dy.assign(static_cast<std::size_t>(ny), 0.0);
  grid.area.assign(static_cast<std::size_t>(ny), 0.0);
  double north = edge(0);
  for (int r = 0; r < ny; ++r) {
    const double south = edge(r + 1);
    const double centre = lat0 + (r + 0.5) * dlat;
    double s12 = 0.0;
    geod.Inverse(centre, 0.0, centre, width, s12);
    grid.dx[static_cast<std::size_t>(r)] = s12;
    geod.Inverse(north, 0.0, south, 0.0, s12);
    grid.dy[static_cast<std::size_t>(r)] = s12;
    grid.area[static_cast<std::size_t>(r)] = quadrangle_area(e, north, south, width);
    north = south;
  }
}

}  // namespace erodem::io
