// erodem — gridded forcing in time (docs/model.md section 3.2, core/band_series.hpp): the air
// temperature of snow.temperature_grids melting a pack at its degree days, a netCDF rain
// variable whose time coordinate gives irregular band times, and the errors of bad grids. Each
// test prints the measured figure beside its bound; an idle solver, bands at the wrong times or
// a lapse correction applied to the grid fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/schema.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "temp_dir.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

class GriddedForcing : public TargetTest {};

constexpr double kDay = 86400.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// `values` on `grid` (georeferenced in metres, no CRS) as a float32 GeoTIFF.
void write_dem(const std::string& path, Grid grid, const std::vector<double>& values) {
  grid.georef.has_transform = true;
  io::write_geotiff(path, grid, std::vector<float>(values.begin(), values.end()), "bed");
}

/// `bands` on `grid` (georeferenced in metres) as a multi-band float32 GeoTIFF.
void write_bands(const std::string& path, Grid grid, const std::vector<std::vector<float>>& bands) {
  grid.georef.has_transform = true;
  io::write_geotiff_bands(path, grid, bands, "gridded forcing");
}

/// The largest |v_i - expect|.
double max_abs_diff(const std::vector<double>& v, double expect) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x - expect));
  return m;
}

TEST_P(GriddedForcing, TemperatureGridsMeltASnowPackAtTheirDegreeDays) {
  // snow.temperature_grids: a three-band GeoTIFF, uniform in space, at the irregular times of
  // snow.temperature_grid_times 0, 1 d and 4 d: -4, -1 and 17 degrees C, held at 17 after 4 d.
  // A flat pack S_0 = 0.3 m on 8 x 8 cells of 10 km, DDF 4 mm/d/K, T_melt 0, retention 0, steps
  // of 1 h (Courant 3600 sqrt(g 0.23) / 1e4 = 0.54). T rises 6 K/d from 1 d and crosses 0 at
  // t_0 = 7/6 d (28 h, a step boundary, as the band times are), so the step-midpoint values
  // integrate the piecewise-linear T exactly: the melt is DDF 3 (t - t_0)^2 K d to 4 d, then
  // 17 K d per day: 40.3 mm by 3 d, 232.3 mm by 6 d. The grid is the temperature at each cell:
  // the lapse rate (-6.5 K/km) with z_ref = -1000 m would cool the cells by 6.5 K and melt 6.8
  // mm by 3 d. Bounds: float64 1e-12 of S_0 (rounding); float32 2e-5 of S_0: 144 subtractions of
  // the step's melt from a pack near 0.3 m, each rounded to half an ulp of 0.3 (1.5e-8 m), are at
  // most 2.1e-6 m = 7e-6 of S_0. An idle pack is off by the melt (0.13 of S_0 at 3 d); bands at
  // the default interval (1 h) melt 17 K for 6 d (0.41 m, more than the pack).
  TempDir dir;
  const Grid g = Grid::uniform(8, 8, 10000.0);
  write_dem(dir.file("dem.tif"), g, std::vector<double>(g.cells(), 0.0));
  std::vector<std::vector<float>> bands;
  for (float T : {-4.0f, -1.0f, 17.0f}) bands.emplace_back(g.cells(), T);
  write_bands(dir.file("t2m.tif"), g, bands);
  const double s0 = 0.3, ddf = 4e-3 / kDay, dt = 3600.0;
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.dem.path = dir.file("dem.tif");
  p.snow.enabled = true;
  p.snow.initial.value = s0;
  p.snow.melt_factor = ddf;
  p.snow.melt_temperature = 0.0;
  p.snow.retention = 0.0;
  p.snow.lapse_rate = -0.0065;
  p.snow.reference_elevation = -1000.0;
  p.snow.temperature_grids = dir.file("t2m.tif");
  apply_setting(p, "snow.temperature_grid_times", "[0, \"1 d\", \"4 d\"]");
  ASSERT_EQ(p.snow.temperature_grid_times, (std::vector<double>{0.0, kDay, 4 * kDay}));
  validate(p);
  auto sim = make_simulation(io::load_terrain(p), p, target());
  auto melt_at = [&](double days) {  // DDF times the degree days of the bands (m)
    const double t0 = 7.0 / 6.0, warm = std::min(days, 4.0) - t0;
    return ddf * kDay * (3.0 * warm * warm + 17.0 * std::max(days - 4.0, 0.0));
  };
  const double bound = this->bound(1e-12, 2e-5) * s0;
  sim.step(72);  // 3 d
  const double e3 = max_abs_diff(sim.field(FieldId::snow), s0 - melt_at(3.0));
  sim.step(72);  // 6 d
  const double e6 = max_abs_diff(sim.field(FieldId::snow), s0 - melt_at(6.0));
  const double e_depth = max_abs_diff(sim.field(FieldId::water_depth), melt_at(6.0));
  const double area = 64 * 1e8;
  const double e_ledger = std::abs(sim.ledger().snow_melted / area - melt_at(6.0));
  std::printf(
      "[temperature grids] %s: melt by 3 d %.4f m, by 6 d %.4f m (closed form); max |snow - "
      "exact| at 3 d %.2e m, at 6 d %.2e m, max |depth - melt| at 6 d %.2e m, |melted / area - "
      "melt| %.2e m (bound %.1e m)\n",
      target().label().c_str(), melt_at(3.0), melt_at(6.0), e3, e6, e_depth, e_ledger, bound);
  auto fig = [&](const char* q) {
    return figure("temperature_grids", "degree_day", q, 10000.0,
                  "S(t) = S0 - DDF integral of max(0, T(t)), T the bands linear in time");
  };
  validation::expect_below(fig("max |snow - exact| at 3 d (m)"), e3, bound);
  validation::expect_below(fig("max |snow - exact| at 6 d (m)"), e6, bound);
  validation::expect_below(fig("max |depth - melt| at 6 d (m)"), e_depth, bound);
  validation::expect_below(fig("|melted / area - melt| at 6 d (m)"), e_ledger, bound);
}

TEST_P(GriddedForcing, NetcdfRainWithIrregularTimesGivesTheTrapezoidIntegral) {
  // rain.grids = NETCDF:"rain.nc":precip (a relative path, resolved against the config's
  // directory): four bands at the time coordinate's 0, 10, 40 and 100 minutes since a date
  // (irregular: 0, 600, 2400, 6000 s), in mm/h, on two closed basins split by a nodata row
  // (rows 0-4 and 6-9 of a 12 x 10 grid of 10 m, a bumpy bed): the north basin 0, 30, 6, 12, the
  // south 10, 0, 0, 20, linear in time between the bands, held after the last. After 2 h each
  // basin holds the trapezoid integral of its bands: north (15 600 + 18 1800 + 9 3600 + 12 1200)
  // / 3600 = 24.5 mm, south (5 600 + 10 3600 + 20 1200) / 3600 = 17.5 mm; the ledger's rain is
  // their sum. Steps of 5 s (the band times are step boundaries: the midpoint values integrate
  // each linear piece exactly). Bounds as RasterParameters.GriddedRainVariesInSpaceAndTime:
  // float64 1e-12; float32 1e-4 (1440 additions of a step's rain to a depth of a few mm, each
  // rounded to half an ulp); the ledger (double) 1e-12. Bands at a regular hour (the file's
  // times ignored) give the north basin 33 mm, bands held until the next the south 8.3 mm.
  TempDir dir;
  const int nx = 12, ny = 10;
  const double dx = 10.0, dt = 5.0, mm_h = 1e-3 / 3600.0;
  Grid g = Grid::uniform(nx, ny, dx);
  g.georef.has_transform = true;
  std::vector<double> bed(g.cells());
  std::vector<std::vector<float>> bands(4, std::vector<float>(g.cells()));
  const float north[4] = {0, 30, 6, 12}, south[4] = {10, 0, 0, 20};
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * nx + c;
      bed[i] = r == 5 ? kNaN : 1.0 + 0.2 * std::sin(0.8 * c) * std::cos(0.7 * r);
      for (int b = 0; b < 4; ++b) bands[b][i] = r < 5 ? north[b] : r > 5 ? south[b] : NAN;
    }
  write_dem(dir.file("dem.tif"), g, bed);
  io::write_netcdf_bands(dir.file("rain.nc"), g, "precip", bands,
                         "minutes since 2026-11-01 00:00:00", {0, 10, 40, 100});
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.dem.path = "dem.tif";
  p.rain.grids = "NETCDF:\"rain.nc\":precip";
  p.flow.manning_n.value = 0.03;
  p.time.duration = 2 * 3600.0;
  resolve_relative_paths(p, dir.path.string());
  EXPECT_EQ(p.rain.grids, "NETCDF:\"" + dir.file("rain.nc") + "\":precip");
  validate(p);
  Terrain terrain = io::load_terrain(p);
  EXPECT_EQ(terrain.rain_grid_times, (std::vector<double>{0, 600, 2400, 6000}));
  auto sim = make_simulation(std::move(terrain), p, target());
  sim.run();
  const Basins basins = basin_volumes(sim, 5);
  const double* volume = basins.volume;
  const double* area = basins.area;
  const double expect[2] = {24.5 * 3600 * mm_h * area[0], 17.5 * 3600 * mm_h * area[1]};
  double worst = 0;
  for (int k = 0; k < 2; ++k) {
    const double e = std::abs(volume[k] - expect[k]) / expect[k];
    worst = std::max(worst, e);
    std::printf(
        "[netcdf rain] %s: %s basin holds %.6g m^3, the trapezoid integral of its bands %.6g "
        "m^3 (relative %.2e, bound %.0e)\n",
        target().label().c_str(), k ? "south" : "north", volume[k], expect[k], e,
        bound(1e-12, 1e-4));
  }
  const double e_ledger =
      std::abs(sim.ledger().rain - expect[0] - expect[1]) / (expect[0] + expect[1]);
  std::printf(
      "[netcdf rain] %s: ledger rain %.6g m^3, integral %.6g m^3 (relative %.1e, bound "
      "1e-12)\n",
      target().label().c_str(), sim.ledger().rain, expect[0] + expect[1], e_ledger);
  auto fig = [&](const char* q) {
    return figure("netcdf_rain", "local_inertial", q, dx,
                  "water = the trapezoid integral of bands at irregular times");
  };
  validation::expect_below(fig("|basin water / integral - 1|"), worst, bound(1e-12, 1e-4));
  validation::expect_below(fig("|ledger rain / integral - 1|"), e_ledger, 1e-12);
}

ERODEM_INSTANTIATE_TARGETS(GriddedForcing);

/// Runs `f`, which must throw an erodem::Error of `code` whose message holds every text of
/// `parts`; prints the message.
void expect_error(const std::function<void()>& f, ExitCode code,
                  const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << parts.front();
  } catch (const Error& e) {
    std::printf("  expected error (%d): %s\n", static_cast<int>(e.code()), e.what());
    EXPECT_EQ(e.code(), code) << e.what();
    for (const auto& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << part << ": " << e.what();
  }
}

TEST(GriddedForcingErrors, BadRasterAndNetcdfGridsAreNamed) {
  // Each bad input is an error naming the key and the file, with the documented exit code:
  // data (65) for what the files hold, no_input (66) for a missing file, config (78) for keys
  // that contradict each other or the file.
  TempDir dir;
  const Grid g = Grid::uniform(6, 4, 100.0);
  write_dem(dir.file("dem.tif"), g, std::vector<double>(g.cells(), 0.0));
  Params base = quiet_params(FlowScheme::local_inertial, 1.0);
  base.dem.path = dir.file("dem.tif");
  base.snow.enabled = true;
  auto temperature = [&](const std::string& file) {
    Params p = base;
    p.snow.temperature_grids = file;
    return p;
  };
  auto rain = [&](const std::string& file) {
    Params p = base;
    p.rain.grids = file;
    return p;
  };
  const std::vector<float> cold(g.cells(), -2.0f);

  // a grid of another size: 7 x 4 on the 6 x 4 DEM
  const Grid wide = Grid::uniform(7, 4, 100.0);
  write_bands(dir.file("wide.tif"), wide, {std::vector<float>(wide.cells(), 1.0f)});
  expect_error([&] { io::load_terrain(temperature(dir.file("wide.tif"))); }, ExitCode::data,
               {"snow.temperature_grids", "wide.tif", "7 x 4", "6 x 4"});
  // kelvin instead of degrees C, and nodata on an active cell
  write_bands(dir.file("kelvin.tif"), g, {cold, std::vector<float>(g.cells(), 271.15f)});
  expect_error([&] { io::load_terrain(temperature(dir.file("kelvin.tif"))); }, ExitCode::data,
               {"snow.temperature_grids", "kelvin.tif", "band 2 value", "[-100"});
  std::vector<float> holed = cold;
  holed[7] = NAN;
  write_bands(dir.file("holed.tif"), g, {cold, holed});
  expect_error([&] { io::load_terrain(temperature(dir.file("holed.tif"))); }, ExitCode::data,
               {"snow.temperature_grids", "holed.tif", "band 2 value", "cell 1, 1"});
  // netCDF: a time coordinate that does not increase, one in months, an unknown variable, a
  // missing file
  const std::vector<std::vector<float>> three(3, std::vector<float>(g.cells(), 1.0f));
  io::write_netcdf_bands(dir.file("back.nc"), g, "precip", three, "hours since 2000-01-01",
                         {0, 2, 1});
  expect_error([&] { io::load_terrain(rain(dir.file("back.nc"))); }, ExitCode::data,
               {"rain.grids", "back.nc", "does not increase", "band 3"});
  io::write_netcdf_bands(dir.file("months.nc"), g, "t2m", three, "months since 2000-01-01",
                         {0, 1, 2});
  expect_error([&] { io::load_terrain(temperature(dir.file("months.nc"))); }, ExitCode::data,
               {"snow.temperature_grids", "months.nc", "months since"});
  expect_error([&] { io::load_terrain(rain("NETCDF:\"" + dir.file("back.nc") + "\":rainfall")); },
               ExitCode::data, {"rain.grids", "back.nc", "no variable 'rainfall'", "precip"});
  expect_error([&] { io::load_terrain(rain("NETCDF:\"" + dir.file("none.nc") + "\":precip")); },
               ExitCode::no_input, {"rain.grids", "none.nc", "no such file"});
  // band times: one per band, increasing, only with grids, and not with a T_ref series
  Params two_times = rain(dir.file("back.nc"));
  two_times.rain.grid_times = {0.0, 60.0};
  expect_error([&] { io::load_terrain(two_times); }, ExitCode::config,
               {"rain.grid_times", "2 times", "back.nc", "3 bands"});
  Params p = base;
  expect_error([&] { apply_setting(p, "rain.grid_times", "[0, 600, 600]"); }, ExitCode::config,
               {"rain.grid_times", "increase"});
  p.rain.grid_times = {0.0, 600.0};
  expect_error([&] { validate(p); }, ExitCode::config, {"rain.grid_times", "rain.grids"});
  Params both = temperature(dir.file("kelvin.tif"));
  apply_setting(both, "snow.air_temperature", "[[0, -5], [3600, 5]]");
  expect_error([&] { validate(both); }, ExitCode::config, {"snow.temperature_grids", "not both"});
}

TEST(GriddedForcingErrors, TemperatureGridUnitsAreReadFromTheBand) {
  // A netCDF t2m in kelvin (ERA5's units: its `units` attribute "K") is converted to degrees C
  // (-273.15; to float rounding of the file's 271.15 and 274.65, 1e-4 K: the float's spacing
  // at 272 K is 3e-5 K); a variable in other units ("m") is refused with exit 65 naming them.
  // Without the conversion the bands would be refused as outside [-100, 100] degrees C. With
  // dem.resample the bands are averaged onto the coarse grid and keep their times.
  TempDir dir;
  const Grid g = Grid::uniform(6, 4, 100.0);
  write_dem(dir.file("dem.tif"), g, std::vector<double>(g.cells(), 0.0));
  Params p = quiet_params(FlowScheme::local_inertial, 1.0);
  p.dem.path = dir.file("dem.tif");
  p.snow.enabled = true;
  const std::vector<std::vector<float>> kelvin{std::vector<float>(g.cells(), 271.15f),
                                               std::vector<float>(g.cells(), 274.65f)};
  io::write_netcdf_bands(dir.file("t2m.nc"), g, "t2m", kelvin, "hours since 2000-01-01", {0, 6},
                         "K");
  p.snow.temperature_grids = dir.file("t2m.nc");
  const Terrain t = io::load_terrain(p);
  ASSERT_EQ(t.temperature_grids.size(), 2u);
  double worst = 0;
  for (std::size_t b = 0; b < 2; ++b)
    for (double v : t.temperature_grids[b])
      worst = std::max(worst, std::abs(v - (b == 0 ? -2.0 : 1.5)));
  std::printf(
      "[temperature units] kelvin to degrees C: max |T - exact| %.1e K (bound 1e-4); "
      "band times %g, %g s\n",
      worst, t.temperature_grid_times[0], t.temperature_grid_times[1]);
  EXPECT_LT(worst, 1e-4);
  EXPECT_EQ(t.temperature_grid_times, (std::vector<double>{0.0, 6 * 3600.0}));
  // dem.resample: the bands averaged onto the coarse grid with the DEM, their times kept
  Params coarse = p;
  coarse.dem.resample_factor = 2;
  const Terrain c = io::load_terrain(coarse);
  ASSERT_EQ(c.grid.cells(), 6u);
  ASSERT_EQ(c.temperature_grids.size(), 2u);
  EXPECT_EQ(c.temperature_grids[1].size(), 6u);
  EXPECT_NEAR(c.temperature_grids[1][5], t.temperature_grids[1][0], 1e-12);
  EXPECT_EQ(c.temperature_grid_times, t.temperature_grid_times);
  io::write_netcdf_bands(dir.file("metres.nc"), g, "t2m", kelvin, "hours since 2000-01-01", {0, 6},
                         "m");
  p.snow.temperature_grids = dir.file("metres.nc");
  expect_error([&] { io::load_terrain(p); }, ExitCode::data,
               {"snow.temperature_grids", "metres.nc", "units 'm'"});
}

}  // namespace
}  // namespace erodem::test
