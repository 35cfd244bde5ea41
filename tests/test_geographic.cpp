// erodem — geographic (lat/lon) DEMs: geodesic cell sizes and exact ellipsoidal cell areas
// on the DEM's own ellipsoid, nodata masks of real DEMs, a run on a geographic grid, and
// `erodem info`.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <GeographicLib/Rhumb.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "erodem/error.hpp"
#include "erodem/io/geodesy.hpp"
#include "erodem/io/raster.hpp"
#include "scenarios.hpp"

namespace fs = std::filesystem;
using erodem::ExitCode;
using erodem::Terrain;

namespace {

const std::string kShared = ERODEM_SHARED_DIR;
const std::string kRhine = kShared + "/data/dem/rhine/rhine_elv0.tif";
const std::string kEno = kShared + "/data/dem/eno/enogeo.tif";
const std::string kDfw = kShared + "/data/dem/dfw/dfw_srtm3.tif";
const std::string kBoulder = kShared + "/data/dem/boulder/srtm_gl3_boulder.asc";
const std::string kTujunga = kShared + "/data/dem/big_tujunga/srtm_bigtujunga30m_utm11.tif";

constexpr double kDegree = 3.14159265358979323846 / 180.0;

template <class F>
ExitCode code_of(F&& f, std::string* msg = nullptr) {
  try {
    f();
  } catch (const erodem::Error& e) {
    if (msg) *msg = e.what();
    return e.code();
  }
  return ExitCode::ok;
}

Terrain read(const std::string& path, const std::string& crs = "") {
  erodem::Params::Dem dem;
  dem.path = path;
  dem.crs = crs;
  return erodem::io::read_dem(dem);
}

/// Sum of all cell areas of the grid (m^2).
double summed_area(const erodem::Grid& g) {
  double sum = 0;
  for (int r = 0; r < g.ny; ++r) sum += g.area[static_cast<std::size_t>(r)] * g.nx;
  return sum;
}

/// The grid's outline: west, east, south, north (degrees).
std::array<double, 4> outline(const erodem::Grid& g) {
  const auto& t = g.georef.transform;
  return {t[0], t[0] + g.nx * t[1], t[3] + g.ny * t[5], t[3]};
}

/// Area of the outline as a rhumb-line polygon: its edges along parallels and meridians are
/// rhumb lines, so four corners describe it exactly.
double rhumb_outline_area(const std::array<double, 4>& o, double a, double f) {
  const GeographicLib::Rhumb rhumb(a, f);
  GeographicLib::PolygonAreaRhumb poly(rhumb);
  poly.AddPoint(o[2], o[0]);
  poly.AddPoint(o[2], o[1]);
  poly.AddPoint(o[3], o[1]);
  poly.AddPoint(o[3], o[0]);
  double perimeter = 0, area = 0;
  poly.Compute(false, true, perimeter, area);
  return std::fabs(area);
}

/// Area of the outline as a geodesic polygon with `n` points along each edge (geodesics
/// between close points follow the parallels up to O(1/n^2) of the area).
double geodesic_outline_area(const std::array<double, 4>& o, double a, double f, int n) {
  const GeographicLib::Geodesic geod(a, f);
  GeographicLib::PolygonArea poly(geod);
  for (int i = 0; i < n; ++i) poly.AddPoint(o[2], o[0] + (o[1] - o[0]) * i / n);  // south
  for (int i = 0; i < n; ++i) poly.AddPoint(o[2] + (o[3] - o[2]) * i / n, o[1]);  // east
  for (int i = 0; i < n; ++i) poly.AddPoint(o[3], o[1] - (o[1] - o[0]) * i / n);  // north
  for (int i = 0; i < n; ++i) poly.AddPoint(o[3] - (o[3] - o[2]) * i / n, o[0]);  // west
  double perimeter = 0, area = 0;
  poly.Compute(false, true, perimeter, area);
  return std::fabs(area);
}

using erodem::test::CliResult;
using erodem::test::run_cli;

/// The number after `"key": ` in a JSON text; NaN when absent.
double json_value(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\": ";
  const auto p = json.find(k);
  if (p == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + p + k.size(), nullptr);
}

}  // namespace

TEST(Geodesy, QuadrangleAreaOfTheWholeEllipsoid) {
  // The closed form against the ellipsoid's total area (GeographicLib::Ellipsoid's formula
  // 4 pi c^2 with the authalic radius c) for WGS84 and a sphere.
  const auto wgs = erodem::io::Ellipsoid::wgs84();
  const double a = wgs.semi_major, f = wgs.flattening();
  const double e2 = f * (2 - f), e = std::sqrt(e2);
  const double c2 = a * a / 2 + (1 - e2) * a * a / (2 * e) * std::atanh(e);
  const double total = 4 * 3.14159265358979323846 * c2;
  const double ours = erodem::io::quadrangle_area(wgs, -90, 90, 360);
  std::printf("  WGS84 total area %.6f km^2, closed form %.6f km^2 (relative %.2e)\n", total * 1e-6,
              ours * 1e-6, (ours - total) / total);
  EXPECT_NEAR(ours / total, 1.0, 1e-14);
  const erodem::io::Ellipsoid sphere{6371000.0, 0.0, "sphere"};
  const double s = erodem::io::quadrangle_area(sphere, 10, 20, 5);
  const double exact =
      6371000.0 * 6371000.0 * 5 * kDegree * (std::sin(20 * kDegree) - std::sin(10 * kDegree));
  EXPECT_NEAR(s / exact, 1.0, 1e-14);
}

TEST(Geographic, RhineCellAreasSumToTheOutline) {
  const Terrain t = read(kRhine);
  const erodem::Grid& g = t.grid;
  ASSERT_TRUE(g.georef.is_geographic);
  ASSERT_TRUE(g.georef.has_transform);
  EXPECT_NE(g.georef.crs_wkt.find("WGS 84"), std::string::npos);
  EXPECT_EQ(g.nx, 997);
  EXPECT_EQ(g.ny, 682);
  const auto o = outline(g);
  std::printf("  rhine outline: lon %.6f .. %.6f, lat %.6f .. %.6f (%.3f degrees of latitude)\n",
              o[0], o[1], o[2], o[3], o[3] - o[2]);
  EXPECT_GT(o[3] - o[2], 5.5);

  const double a = GeographicLib::Constants::WGS84_a(), f = GeographicLib::Constants::WGS84_f();
  const double sum = summed_area(g);
  const double rhumb = rhumb_outline_area(o, a, f);
  const double geodesic = geodesic_outline_area(o, a, f, 20000);
  const double rel = std::fabs(sum - rhumb) / rhumb;
  const double rel_geod = std::fabs(sum - geodesic) / geodesic;
  std::printf(
      "  summed cell area %.6f km^2; outline (rhumb polygon, exact) %.6f km^2: relative "
      "%.2e (bound 1e-9); outline (geodesic polygon, 20000 points per edge) %.6f km^2: "
      "relative %.2e (bound 1e-9)\n",
      sum * 1e-6, rhumb * 1e-6, rel, geodesic * 1e-6, rel_geod);
  EXPECT_LT(rel, 1e-9);
  EXPECT_LT(rel_geod, 1e-9);

  // dy: the row heights add up to the meridian arc between the outline's north and south.
  double dy_sum = 0;
  for (double dy : g.dy) dy_sum += dy;
  double arc = 0;
  GeographicLib::Geodesic(a, f).Inverse(o[3], 0.0, o[2], 0.0, arc);
  std::printf("  summed dy %.6f m, meridian arc %.6f m: relative %.2e\n", dy_sum, arc,
              (dy_sum - arc) / arc);
  EXPECT_NEAR(dy_sum / arc, 1.0, 1e-12);
}

TEST(Geographic, RhineDxShrinksNorthwardsByCosLatitude) {
  const Terrain t = read(kRhine);
  const erodem::Grid& g = t.grid;
  const auto& tr = g.georef.transform;
  const double lat_n = tr[3] + 0.5 * tr[5], lat_s = tr[3] + (g.ny - 0.5) * tr[5];
  const double ratio = g.dx.front() / g.dx.back();
  const double cos_ratio = std::cos(lat_n * kDegree) / std::cos(lat_s * kDegree);
  // On the ellipsoid the parallel's radius is a cos(lat) / sqrt(1 - e^2 sin^2(lat)).
  const double f = GeographicLib::Constants::WGS84_f(), e2 = f * (2 - f);
  auto radius = [&](double lat) {
    const double s = std::sin(lat * kDegree);
    return std::cos(lat * kDegree) / std::sqrt(1 - e2 * s * s);
  };
  const double ell_ratio = radius(lat_n) / radius(lat_s);
  std::printf(
      "  dx north %.6f m (lat %.4f), south %.6f m (lat %.4f): ratio %.9f; cos ratio "
      "%.9f (differs %.2e, bound 1e-3); ellipsoidal parallel ratio %.12f (differs "
      "%.2e, bound 1e-9)\n",
      g.dx.front(), lat_n, g.dx.back(), lat_s, ratio, cos_ratio, ratio / cos_ratio - 1, ell_ratio,
      ratio / ell_ratio - 1);
  EXPECT_LT(g.dx.front(), g.dx.back());
  EXPECT_NEAR(ratio / cos_ratio, 1.0, 1e-3);
  EXPECT_NEAR(ratio / ell_ratio, 1.0, 1e-9);
  for (int r = 1; r < g.ny; ++r) ASSERT_LT(g.dx[r - 1], g.dx[r]) << "row " << r;
}

TEST(Geographic, EnoUsesTheGrs80EllipsoidOfNad83) {
  const Terrain t = read(kEno);
  const erodem::Grid& g = t.grid;
  ASSERT_TRUE(g.georef.is_geographic);
  EXPECT_NE(g.georef.crs_wkt.find("GRS 1980"), std::string::npos);
  const auto info = erodem::io::describe_crs(g.georef.crs_wkt);
  EXPECT_TRUE(info.geographic);
  EXPECT_EQ(info.ellipsoid.name, "GRS 1980");
  EXPECT_DOUBLE_EQ(info.ellipsoid.inverse_flattening, 298.257222101);

  // dx of a row against a GRS80 and a WGS84 geodesic between the same two cell centres.
  const auto grs = erodem::io::Ellipsoid::grs80();
  const GeographicLib::Geodesic g_grs(grs.semi_major, grs.flattening());
  const GeographicLib::Geodesic g_wgs(GeographicLib::Constants::WGS84_a(),
                                      GeographicLib::Constants::WGS84_f());
  const auto& tr = g.georef.transform;
  double worst_grs = 0, least_wgs = 1;
  for (int r = 0; r < g.ny; r += 97) {
    const double lat = tr[3] + (r + 0.5) * tr[5];
    double s_grs = 0, s_wgs = 0;
    g_grs.Inverse(lat, 0.0, lat, tr[1], s_grs);
    g_wgs.Inverse(lat, 0.0, lat, tr[1], s_wgs);
    worst_grs = std::max(worst_grs, std::fabs(g.dx[r] / s_grs - 1));
    least_wgs = std::min(least_wgs, std::fabs(g.dx[r] / s_wgs - 1));
  }
  // The two ellipsoids differ by 1.6e-11 in flattening: a 6e-12 relative change of dx here.
  std::printf("  eno dx vs GRS80 geodesic: worst relative %.2e; vs WGS84: least relative %.2e\n",
              worst_grs, least_wgs);
  EXPECT_LT(worst_grs, 1e-13);
  EXPECT_GT(least_wgs, 3e-12);

  // Areas: the cells sum to the GRS80 outline.
  const auto o = outline(g);
  const double sum = summed_area(g);
  const double outline_grs = rhumb_outline_area(o, grs.semi_major, grs.flattening());
  const double outline_wgs = rhumb_outline_area(o, GeographicLib::Constants::WGS84_a(),
                                                GeographicLib::Constants::WGS84_f());
  const double rel = std::fabs(sum - outline_grs) / outline_grs;
  std::printf(
      "  eno summed area %.9f km^2, GRS80 outline %.9f km^2: relative %.2e (bound 1e-9); "
      "the WGS84 outline differs by %.2e\n",
      sum * 1e-6, outline_grs * 1e-6, rel, (outline_wgs - outline_grs) / outline_grs);
  EXPECT_LT(rel, 1e-9);
}

TEST(Geographic, BoulderWithEpsg4326ReadsAsGeographic) {
  // Boulder's ESRI ASCII grid has no .prj: without dem.crs it needs a config choice.
  std::string msg;
  EXPECT_EQ(code_of([&] { read(kBoulder); }, &msg), ExitCode::config);
  EXPECT_NE(msg.find("dem.crs"), std::string::npos) << msg;

  const Terrain t = read(kBoulder, "EPSG:4326");
  const erodem::Grid& g = t.grid;
  EXPECT_TRUE(g.georef.is_geographic);
  EXPECT_TRUE(g.georef.has_transform);
  EXPECT_NE(g.georef.crs_wkt.find("WGS 84"), std::string::npos);
  EXPECT_EQ(g.nx, 758);
  EXPECT_EQ(g.ny, 758);
  std::printf("  boulder (EPSG:4326): dx %.4f .. %.4f m, dy %.4f m, area %.3f km^2\n", g.dx.front(),
              g.dx.back(), g.dy[0], summed_area(g) * 1e-6);
  // 3 arc-seconds at 40 degrees north: about 71 m east-west and 92.5 m north-south.
  EXPECT_NEAR(g.dx[379], 71.0, 0.5);
  EXPECT_NEAR(g.dy[379], 92.5, 0.2);
  const auto o = outline(g);
  const double rel =
      std::fabs(summed_area(g) / rhumb_outline_area(o, 6378137.0, 1 / 298.257223563) - 1);
  EXPECT_LT(rel, 1e-9);

  // A geographic CRS cannot come with a cell size in metres, nor a metre resample.
  erodem::Params::Dem dem;
  dem.path = kBoulder;
  dem.crs = "EPSG:4326";
  dem.resample = 300.0;
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }, &msg), ExitCode::config);
  EXPECT_NE(msg.find("integer factor"), std::string::npos) << msg;
}

TEST(Geographic, CoarseningRecomputesCellsOnTheEllipsoid) {
  erodem::Params::Dem dem;
  dem.path = kDfw;
  const Terrain fine = erodem::io::read_dem(dem);
  dem.resample_factor = 4;
  const Terrain coarse = erodem::io::read_dem(dem);
  ASSERT_TRUE(coarse.grid.georef.is_geographic);
  EXPECT_EQ(coarse.grid.nx, 367 / 4);
  EXPECT_EQ(coarse.grid.ny, 359 / 4);
  // Each coarse cell is exactly the 4 x 4 fine cells it averages.
  for (int r = 0; r < coarse.grid.ny; ++r) {
    double fine_area = 0, fine_dy = 0;
    for (int k = 0; k < 4; ++k) {
      fine_area += 16 * fine.grid.area[static_cast<std::size_t>(4 * r + k)] / 4;
      fine_dy += fine.grid.dy[static_cast<std::size_t>(4 * r + k)];
    }
    ASSERT_NEAR(coarse.grid.area[r] / fine_area, 1.0, 1e-12) << "row " << r;
    // The coarse edges lat0 + k (4 dlat) and the fine ones lat0 + (4k) dlat differ by
    // rounding (1e-14 degrees, 1e-9 m): 2e-12 of a 370 m row measured on DFW.
    ASSERT_NEAR(coarse.grid.dy[r] / fine_dy, 1.0, 1e-10) << "row " << r;
    const double fine_dx = 4 * fine.grid.dx[static_cast<std::size_t>(4 * r + 2)];
    ASSERT_NEAR(coarse.grid.dx[r] / fine_dx, 1.0, 1e-4) << "row " << r;
  }
}

TEST(Geographic, NodataBecomesTheMask) {
  // Rhine: -9999 outside the basin, about half of the cells.
  const Terrain rhine = read(kRhine);
  ASSERT_EQ(rhine.mask.size(), rhine.grid.cells());
  std::size_t masked = 0;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (std::size_t i = 0; i < rhine.bed.size(); ++i) {
    if (!rhine.active(i)) {
      ++masked;
      ASSERT_TRUE(std::isnan(rhine.bed[i])) << i;
      continue;
    }
    lo = std::min(lo, rhine.bed[i]);
    hi = std::max(hi, rhine.bed[i]);
  }
  const double frac = static_cast<double>(masked) / static_cast<double>(rhine.grid.cells());
  std::printf("  rhine: %zu of %zu cells nodata (%.2f %%), valid %.1f .. %.1f m\n", masked,
              rhine.grid.cells(), 100 * frac, lo, hi);
  EXPECT_NEAR(frac, 0.5, 0.05);
  EXPECT_GE(lo, 0.0);  // no -9999 among the valid cells
  EXPECT_NEAR(hi, 3532.1, 0.01);

  // DFW declares -32768 but has no such cell; a copy of a window with holes of that value.
  erodem::Params::Dem dem;
  dem.path = kDfw;
  dem.window = std::array<int, 4>{10, 20, 60, 50};
  const Terrain dfw = erodem::io::read_dem(dem);
  EXPECT_TRUE(dfw.mask.empty());
  EXPECT_TRUE(dfw.grid.georef.is_geographic);
  std::vector<float> v(dfw.bed.begin(), dfw.bed.end());
  for (std::size_t i = 0; i < v.size(); i += 7) v[i] = -32768.0f;
  const fs::path dir = fs::temp_directory_path() / "erodem_geographic_nodata";
  fs::create_directories(dir);
  const std::string out = (dir / "dfw_holes.tif").string();
  erodem::io::write_geotiff(out, dfw.grid, v, "dfw with holes", -32768.0);
  erodem::Params::Dem d2;
  d2.path = out;
  const Terrain holes = erodem::io::read_dem(d2);
  fs::remove_all(dir);
  ASSERT_EQ(holes.mask.size(), v.size());
  EXPECT_TRUE(holes.grid.georef.is_geographic);  // the CRS survives the round trip
  EXPECT_NEAR(holes.grid.area[7] / dfw.grid.area[7], 1.0, 1e-12);
  for (std::size_t i = 0; i < v.size(); ++i) {
    ASSERT_EQ(holes.mask[i], i % 7 == 0 ? 0 : 1) << i;
    if (i % 7 != 0) {
      ASSERT_EQ(holes.bed[i], dfw.bed[i]) << i;
    }
  }
}

TEST(Geographic, RhineRunsWithItsNodataMask) {
  using namespace erodem;
  Terrain t = read(kRhine);
  const std::vector<std::uint8_t> mask = t.mask;
  Params p = test::quiet_params(FlowScheme::pipes, 10.0);
  p.rain.rate = 100e-3 / 3600;  // 100 mm/h
  p.time.steps = 20;
  Simulation sim = test::make_simulation(std::move(t), p, {"cpu", Precision::float64});
  sim.step(20);
  const Ledger& l = sim.ledger();
  std::printf(
      "  rhine, 20 steps of 10 s, 100 mm/h: water %.6e m^3, rain %.6e m^3, closure "
      "%.3e m^3 (relative %.2e)\n",
      l.water, l.rain, l.closure_error(), l.relative_closure_error());
  EXPECT_GT(l.rain, 0.0);
  EXPECT_LT(std::fabs(l.relative_closure_error()), 1e-12);
  // The rain fell on the valid cells' area only.
  double valid_area = 0;
  const Grid& g = sim.grid();
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c)
      if (mask[static_cast<std::size_t>(r) * g.nx + c]) valid_area += g.area[r];
  EXPECT_NEAR(l.rain / (valid_area * p.rain.rate * 200.0), 1.0, 1e-12);
  const auto depth = sim.field(FieldId::water_depth);
  std::size_t wet_nodata = 0;
  for (std::size_t i = 0; i < depth.size(); ++i)
    if (mask[i] == 0 && depth[i] != 0.0) ++wet_nodata;
  EXPECT_EQ(wet_nodata, 0u);
}

TEST(GeographicCli, InfoOnBigTujungaIsProjected) {
  const auto text = run_cli("info '" + kTujunga + "'");
  ASSERT_EQ(text.code, 0) << text.output;
  EXPECT_NE(text.output.find("1197 x 643"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("UTM zone 11N (EPSG:32611), projected"), std::string::npos)
      << text.output;
  EXPECT_NE(text.output.find("dx 30 m, dy 30 m"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("315 .. 2295 m"), std::string::npos) << text.output;

  const auto json = run_cli("info --json '" + kTujunga + "'");
  ASSERT_EQ(json.code, 0) << json.output;
  EXPECT_NE(json.output.find("\"kind\": \"projected\""), std::string::npos) << json.output;
  EXPECT_NE(json.output.find("\"authority\": \"EPSG:32611\""), std::string::npos);
  EXPECT_EQ(json_value(json.output, "nx"), 1197);
  EXPECT_EQ(json_value(json.output, "ny"), 643);
  EXPECT_EQ(json_value(json.output, "dx_min"), 30);
  EXPECT_EQ(json_value(json.output, "dy_max"), 30);
  EXPECT_EQ(json_value(json.output, "min"), 315);
  EXPECT_EQ(json_value(json.output, "max"), 2295);
  EXPECT_EQ(json_value(json.output, "nodata_fraction"), 0);
  EXPECT_NEAR(json_value(json.output, "total"), 1197 * 643 * 900e-6, 1e-6);
  EXPECT_NE(json.output.find("\"sha256\": \""), std::string::npos);
}

TEST(GeographicCli, InfoOnRhineIsGeographic) {
  const auto text = run_cli("info '" + kRhine + "'");
  ASSERT_EQ(text.code, 0) << text.output;
  EXPECT_NE(text.output.find("WGS 84 (EPSG:4326), geographic"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("ellipsoid  WGS 84"), std::string::npos) << text.output;

  const auto json = run_cli("info --json '" + kRhine + "'");
  ASSERT_EQ(json.code, 0) << json.output;
  std::printf("%s", json.output.c_str());
  EXPECT_NE(json.output.find("\"kind\": \"geographic\""), std::string::npos);
  EXPECT_NEAR(json_value(json.output, "nodata_fraction"), 0.5, 0.05);
  EXPECT_NEAR(json_value(json.output, "inverse_flattening"), 298.257223563, 1e-9);
  const double north = json_value(json.output, "dx_north"),
               south = json_value(json.output, "dx_south");
  EXPECT_LT(north, south);
  EXPECT_NEAR(json_value(json.output, "dx_min"), north, 1e-6);
  EXPECT_NEAR(json_value(json.output, "west"), 3.5667, 1e-4);
  EXPECT_NEAR(json_value(json.output, "north"), 52.0083, 1e-4);
}

TEST(GeographicCli, InfoWithoutGeoreferencingSaysWhatIsNeeded) {
  const auto r = run_cli("info '" + kBoulder + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("dem.crs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("EPSG:4326"), std::string::npos) << r.output;
  const auto g = run_cli("info --json --crs EPSG:4326 '" + kBoulder + "'");
  EXPECT_EQ(g.code, 0) << g.output;
  EXPECT_NE(g.output.find("\"kind\": \"geographic\""), std::string::npos) << g.output;
}

TEST(GeographicCli, InfoExitCodes) {
  const auto missing = run_cli("info /nonexistent/dem.tif");
  EXPECT_EQ(missing.code, 66) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent/dem.tif"), std::string::npos);
  const fs::path bad = fs::temp_directory_path() / "erodem_info_not_a_raster.tif";
  std::FILE* f = std::fopen(bad.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs("not a raster\n", f);
  std::fclose(f);
  const auto unreadable = run_cli("info '" + bad.string() + "'");
  fs::remove(bad);
  EXPECT_EQ(unreadable.code, 65) << unreadable.output;
}
