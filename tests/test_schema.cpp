// Tests of the parameter schema: units, TOML parsing, --set, validation, dump round trip,
// and config-file errors with their exit codes.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/params.hpp"
#include "erodem/schema.hpp"
#include "erodem/units.hpp"

namespace {

using erodem::Dimension;
using erodem::Error;
using erodem::ExitCode;
using erodem::Params;

/// Parses TOML text through the schema, as a file named "config.toml".
Params from_text(const std::string& text) {
  return erodem::params_from_toml(toml::parse(text), "config.toml");
}

/// The message of the config error thrown by `f`; fails the test when none is thrown.
template <class F>
std::string config_error_message(F f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::config) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no erodem::Error thrown";
  return "";
}

/// A minimal valid parameter set.
Params valid_params() {
  Params p;
  p.dem.path = "dem.tif";
  return p;
}

/// Writes `text` to a fresh file in the test temp dir and returns its path.
std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "erodem_test_schema";
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

void expect_quantity(const std::string& text, Dimension dim, double expected) {
  const auto v = erodem::try_parse_quantity(text, dim);
  ASSERT_TRUE(v.has_value()) << text;
  EXPECT_NEAR(*v, expected, std::abs(expected) * 1e-12) << text << " -> " << *v;
}

// ---- units ------------------------------------------------------------------------------

TEST(Units, LengthUnits) {
  expect_quantity("160 m", Dimension::length, 160.0);
  expect_quantity("5 cm", Dimension::length, 0.05);
  expect_quantity("3 mm", Dimension::length, 0.003);
  expect_quantity("0.5 km", Dimension::length, 500.0);
  expect_quantity("  12.5  ", Dimension::length, 12.5);
}

TEST(Units, TimeUnits) {
  expect_quantity("5 s", Dimension::time, 5.0);
  expect_quantity("10 min", Dimension::time, 600.0);
  expect_quantity("6 h", Dimension::time, 21600.0);
  expect_quantity("2 d", Dimension::time, 172800.0);
}

TEST(Units, SpeedUnits) {
  expect_quantity("20 mm/h", Dimension::speed, 0.02 / 3600.0);
  expect_quantity("3 mm/d", Dimension::speed, 0.003 / 86400.0);
  expect_quantity("1e-6 m/s", Dimension::speed, 1e-6);
  expect_quantity("2 cm/h", Dimension::speed, 0.02 / 3600.0);
  expect_quantity("1 m/h", Dimension::speed, 1.0 / 3600.0);
  expect_quantity("4 mm/s", Dimension::speed, 0.004);
  expect_quantity("20mm/h", Dimension::speed, 0.02 / 3600.0);
}

TEST(Units, AngleAndInverseTime) {
  expect_quantity("35 deg", Dimension::angle, 35.0);
  expect_quantity("35 degrees", Dimension::angle, 35.0);
  expect_quantity("0.5 1/s", Dimension::inverse_time, 0.5);
  expect_quantity("36 1/h", Dimension::inverse_time, 0.01);
  expect_quantity("864 1/d", Dimension::inverse_time, 0.01);
  expect_quantity("0.25", Dimension::dimensionless, 0.25);
}

TEST(Units, WrongUnitIsRejectedWithAcceptedList) {
  std::string why;
  EXPECT_FALSE(erodem::try_parse_quantity("20 mm/h", Dimension::length, &why));
  EXPECT_NE(why.find("mm/h"), std::string::npos) << why;
  EXPECT_NE(why.find("m, cm, mm, km"), std::string::npos) << why;
  EXPECT_FALSE(erodem::try_parse_quantity("5 kg", Dimension::time));
  EXPECT_FALSE(erodem::try_parse_quantity("m", Dimension::length));
  EXPECT_FALSE(erodem::try_parse_quantity("", Dimension::length));
  EXPECT_FALSE(erodem::try_parse_quantity("nan m", Dimension::length));
  EXPECT_FALSE(erodem::try_parse_quantity("0x10 m", Dimension::length));
  EXPECT_FALSE(erodem::try_parse_quantity("3 m", Dimension::dimensionless));
}

TEST(Units, ParseQuantityErrorNamesKey) {
  const std::string msg = config_error_message(
      [] { erodem::parse_quantity("6 furlongs", Dimension::time, "time.duration", "run.toml"); });
  EXPECT_EQ(msg.rfind("run.toml: 'time.duration': ", 0), 0u) << msg;
  EXPECT_NE(msg.find("s, min, h, d"), std::string::npos) << msg;
}

TEST(Units, FormatNumberRoundTrips) {
  for (double v : {0.0, 1.0, 0.05, 1e-6, 20.0 / 3.6e6, 1234567.891, -3.5, 1e300}) {
    const std::string s = erodem::format_number(v);
    EXPECT_EQ(std::stod(s), v) << s;
    EXPECT_NE(s.find_first_of(".e"), std::string::npos) << s;
  }
}

// ---- TOML -------------------------------------------------------------------------------

TEST(Schema, ParsesTheInterfacesExample) {
  const Params p = from_text(R"(
[dem]
path = "dem.tif"
window = [0, 0, 512, 512]
resample = "320 m"
z_scale = 0.1
cell_size = "160 m"
crs = "EPSG:32610"
[initial]
water_level = 10.0
[time]
duration = "6 h"
dt = 0.05
adaptive = true
cfl = 0.7
dt_max = "5 s"
[flow]
scheme = "pipes"
manning_n = "n.tif"
theta = 0.8
pipe_area = 1.0
pipe_length = "cell"
[rain]
series = [[0, "0 mm/h"], [600, "40 mm/h"], ["1 h", "0 mm/h"]]
raster = "rain_factor.tif"
[[inflow]]
line = [[0.0, 990.0], [0.0, 1010.0]]
hydrograph = [[0, 0.0], [3000, 20.0], [21600, 0.0]]
[[inflow]]
point = [5.0, 6.0]
hydrograph = [[0, 1.0]]
[erosion]
enabled = true
sediment_capacity = 1.0
hardness = 0.5
bedrock_level = -20
[transport]
scheme = "semi_lagrangian"
[thermal]
talus_angle = "30 deg"
rate = 0.15
[evaporation]
rate = "0.36 1/h"
[boundary]
north = "open"
east = "fixed_level"
sea_level = 0.0
nodata = "sea"
[output]
path = "run.h5"
interval = "10 min"
fields = ["bed", "water_depth", "wetness"]
gauges = [[50.0, 1000.0], [300.0, 1300.0]]
[numerics]
precision = "float64"
)");
  EXPECT_EQ(p.dem.path, "dem.tif");
  ASSERT_TRUE(p.dem.window.has_value());
  EXPECT_EQ((*p.dem.window)[2], 512);
  EXPECT_EQ(p.dem.resample, 320.0);
  EXPECT_EQ(p.dem.resample_factor, 0);
  EXPECT_EQ(p.dem.cell_size, 160.0);
  EXPECT_EQ(p.initial.water_level, 10.0);
  EXPECT_EQ(p.time.duration, 21600.0);
  EXPECT_EQ(p.time.dt_max, 5.0);
  EXPECT_EQ(p.flow.scheme, erodem::FlowScheme::pipes);
  EXPECT_EQ(p.flow.manning_n.path, "n.tif");
  EXPECT_EQ(p.flow.pipe_length, 0.0);
  ASSERT_EQ(p.rain.series.size(), 3u);
  EXPECT_EQ(p.rain.series[2].t, 3600.0);
  EXPECT_NEAR(p.rain.series[1].value, 0.04 / 3600.0, 1e-18) << p.rain.series[1].value;
  ASSERT_EQ(p.inflow.size(), 2u);
  EXPECT_EQ(p.inflow[0].vertices.size(), 2u);
  EXPECT_EQ(p.inflow[0].hydrograph[1].value, 20.0);
  EXPECT_EQ(p.inflow[1].vertices.size(), 1u);
  EXPECT_EQ(p.erosion.hardness.value, 0.5);
  EXPECT_FALSE(p.erosion.hardness.is_raster());
  EXPECT_EQ(p.erosion.bedrock_level, -20.0);
  EXPECT_EQ(p.transport.scheme, erodem::TransportScheme::semi_lagrangian);
  EXPECT_EQ(p.thermal.talus_angle, 30.0);
  EXPECT_NEAR(p.evaporation.rate, 1e-4, 1e-16) << p.evaporation.rate;
  EXPECT_EQ(p.boundary.north, erodem::BoundaryKind::open);
  EXPECT_EQ(p.boundary.east, erodem::BoundaryKind::fixed_level);
  EXPECT_EQ(p.boundary.nodata, erodem::NodataKind::sea);
  EXPECT_EQ(p.output.interval, 600.0);
  EXPECT_EQ(p.output.fields.size(), 3u);
  EXPECT_EQ(p.output.gauges.size(), 2u);
  EXPECT_EQ(p.numerics.precision, erodem::Precision::float64);
  EXPECT_NO_THROW(erodem::validate(p));
}

TEST(Schema, RainRateWithUnit) {
  const Params p = from_text("[rain]\nrate = \"20 mm/h\"\n");
  EXPECT_NEAR(p.rain.rate, 0.02 / 3600.0, 1e-18) << p.rain.rate;
}

TEST(Schema, ResampleIntegerIsAFactor) {
  const Params p = from_text("[dem]\nresample = 4\n");
  EXPECT_EQ(p.dem.resample_factor, 4);
  EXPECT_EQ(p.dem.resample, 0.0);
}

TEST(Schema, UnknownKeyNamesKeyFileAndSuggestion) {
  const std::string msg = config_error_message([] { from_text("[rain]\nrat = 1.0\n"); });
  EXPECT_EQ(msg.rfind("config.toml: 'rain.rat': ", 0), 0u) << msg;
  EXPECT_NE(msg.find("did you mean 'rain.rate'"), std::string::npos) << msg;
}

TEST(Schema, UnknownTableAndMisplacedKey) {
  std::string msg = config_error_message([] { from_text("[rian]\nrate = 1.0\n"); });
  EXPECT_NE(msg.find("'rian': unknown table; did you mean [rain]?"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("dt = 0.1\n"); });
  EXPECT_NE(msg.find("'dt': unknown parameter; did you mean 'time.dt'"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("rain = 5\n"); });
  EXPECT_NE(msg.find("'rain': expected a table"), std::string::npos) << msg;
}

TEST(Schema, NegativeRateError) {
  const std::string msg = config_error_message([] { from_text("[rain]\nrate = -5\n"); });
  EXPECT_EQ(msg,
            "config.toml: 'rain.rate': expected a rate in [0, 1] (m/s, or a string like \"20 "
            "mm/h\"), got -5");
}

TEST(Schema, TypeErrors) {
  std::string msg = config_error_message([] { from_text("[time]\ndt = true\n"); });
  EXPECT_NE(msg.find("'time.dt': expected a duration > 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got true"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[time]\nsteps = 1.5\n"); });
  EXPECT_NE(msg.find("'time.steps': expected an integer >= 1"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[time]\nadaptive = 1\n"); });
  EXPECT_NE(msg.find("'time.adaptive': expected a boolean"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[flow]\nscheme = \"pipe\"\n"); });
  EXPECT_NE(msg.find("expected one of pipes | local_inertial | shallow_water, got \"pipe\""),
            std::string::npos)
      << msg;
  msg = config_error_message([] { from_text("[time]\ndt = \"5 mm\"\n"); });
  EXPECT_NE(msg.find("'time.dt': unit 'mm'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("s, min, h, d"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[dem]\nwindow = [0, 0, 0, 5]\n"); });
  EXPECT_NE(msg.find("'dem.window': expected width > 0"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[thermal]\ntalus_angle = 90\n"); });
  EXPECT_NE(msg.find("in (0, 90)"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[output]\nfields = [\"bed\", \"speed\"]\n"); });
  EXPECT_NE(msg.find("unknown name \"speed\""), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[time]\ndt = nan\n"); });
  EXPECT_NE(msg.find("got nan"), std::string::npos) << msg;
}

TEST(Schema, SeriesTimesMustIncrease) {
  const std::string msg = config_error_message(
      [] { from_text("[rain]\nseries = [[0, 1e-6], [600, 0.0], [300, 0.0]]\n"); });
  EXPECT_NE(msg.find("'rain.series[2]': times must increase"), std::string::npos) << msg;
}

TEST(Schema, InflowErrors) {
  std::string msg = config_error_message(
      [] { from_text("[[inflow]]\npoint = [0.0, 1.0]\nhydrograph = [[0, 1.0]]\nq = 3\n"); });
  EXPECT_NE(msg.find("'inflow[0].q': unknown inflow key"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[[inflow]]\npoint = [0.0, 1.0]\n"); });
  EXPECT_NE(msg.find("'inflow[0].hydrograph'"), std::string::npos) << msg;
}

TEST(Schema, InflowSedimentAndErosionLayers) {
  // An inflow's sediment concentration (a volume fraction in [0, 1)), the erosion law and the
  // nested bed-layer keys with their units, and the errors that name them.
  Params p = from_text(
      "[dem]\nsynthetic = \"hill\"\n[erosion]\nenabled = true\nlaw = \"physical\"\nsoil_thickness "
      "= \"30 cm\"\n"
      "[erosion.bedrock]\nclosure = \"cohesive\"\nerosion_rate = \"2 g/m^2/s\"\n"
      "critical_shear = \"1 kPa\"\n"
      "[[inflow]]\npoint = [0.0, 1.0]\nhydrograph = [[0, 1.0]]\nsediment_concentration = 0.01\n");
  EXPECT_EQ(p.inflow[0].sediment_concentration, 0.01);
  EXPECT_NEAR(p.erosion.soil_thickness.value, 0.3, 1e-15);
  EXPECT_NEAR(p.erosion.bedrock.erosion_rate, 2e-3, 1e-15);
  EXPECT_EQ(p.erosion.bedrock.critical_shear, 1000.0);
  validate(p, "test");
  std::string msg = config_error_message([] {
    from_text(
        "[[inflow]]\npoint = [0.0, 1.0]\nhydrograph = [[0, 1.0]]\n"
        "sediment_concentration = 1.5\n");
  });
  EXPECT_NE(msg.find("'inflow[0].sediment_concentration'"), std::string::npos) << msg;
  msg = config_error_message([] {
    Params q = from_text(
        "[dem]\nsynthetic = \"hill\"\n[[inflow]]\npoint = [0.0, 1.0]\n"
        "hydrograph = [[0, 1.0]]\nsediment_concentration = 0.1\n");
    validate(q, "test");
  });
  EXPECT_NE(msg.find("erosion.enabled"), std::string::npos) << msg;
  // the boundary's sediment too: without erosion it is refused, not silently dropped
  msg = config_error_message([] {
    Params q = from_text(
        "[dem]\nsynthetic = \"hill\"\n[boundary]\nwest = \"fixed_level\"\n"
        "sediment_concentration = 0.02\n");
    validate(q, "test");
  });
  EXPECT_NE(msg.find("'boundary.sediment_concentration'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("erosion.enabled"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[erosion.soil]\ncritical_shear = \"2 m\"\n"); });
  EXPECT_NE(msg.find("'erosion.soil.critical_shear'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Pa"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[erosion]\nlaw = \"meii\"\n"); });
  EXPECT_NE(msg.find("mei"), std::string::npos) << msg;
}

TEST(Schema, ScalarOrRaster) {
  Params p = from_text("[initial]\nwater_depth = \"2020_depth.tif\"\n");
  EXPECT_EQ(p.initial.water_depth.path, "2020_depth.tif");
  p = from_text("[initial]\nwater_depth = \"20 cm\"\n");
  EXPECT_FALSE(p.initial.water_depth.is_raster());
  EXPECT_NEAR(p.initial.water_depth.value, 0.2, 1e-15) << p.initial.water_depth.value;
  const std::string msg =
      config_error_message([] { from_text("[initial]\nwater_depth = \"2 mm/h\"\n"); });
  EXPECT_NE(msg.find("'initial.water_depth'"), std::string::npos) << msg;
}

TEST(Schema, HardnessNoise) {
  // erosion.hardness takes "noise" besides a number and a raster path, with its four keys
  // (the scale a length: units accepted).
  Params p = from_text(
      "[erosion]\nhardness = \"noise\"\nnoise_amplitude = 0.25\nnoise_scale = \"2 km\"\n"
      "noise_octaves = 7\nnoise_seed = -3\n");
  EXPECT_TRUE(p.erosion.hardness_noise);
  EXPECT_FALSE(p.erosion.hardness.is_raster());
  EXPECT_EQ(p.erosion.noise_amplitude, 0.25);
  EXPECT_EQ(p.erosion.noise_scale, 2000.0);
  EXPECT_EQ(p.erosion.noise_octaves, 7);
  EXPECT_EQ(p.erosion.noise_seed, -3);
  // Defaults: amplitude 0.5, 500 m, 5 octaves, seed 1; a number or a path is not noise.
  const Params d;
  EXPECT_FALSE(d.erosion.hardness_noise);
  EXPECT_EQ(d.erosion.noise_amplitude, 0.5);
  EXPECT_EQ(d.erosion.noise_scale, 500.0);
  EXPECT_EQ(d.erosion.noise_octaves, 5);
  EXPECT_EQ(d.erosion.noise_seed, 1);
  EXPECT_EQ(erodem::parameter_info("erosion.noise_scale").unit, "m");
  EXPECT_FALSE(from_text("[erosion]\nhardness = 0.5\n").erosion.hardness_noise);
  EXPECT_EQ(from_text("[erosion]\nhardness = \"h.tif\"\n").erosion.hardness.path, "h.tif");
  // --set: "noise", then a number again (which clears it).
  p = valid_params();
  erodem::apply_setting(p, "erosion.hardness", "noise");
  EXPECT_TRUE(p.erosion.hardness_noise);
  erodem::apply_setting(p, "erosion.hardness", "0.75");
  EXPECT_FALSE(p.erosion.hardness_noise);
  EXPECT_EQ(p.erosion.hardness.value, 0.75);
  // Rejected, naming the key and what it accepts: a typo of "noise" (a bare word, not a
  // raster file name), and values out of range.
  std::string msg = config_error_message([] { from_text("[erosion]\nhardness = \"nois\"\n"); });
  EXPECT_NE(msg.find("'erosion.hardness': expected a number in [0, 1], a raster path or "
                     "\"noise\", got \"nois\""),
            std::string::npos)
      << msg;
  msg = config_error_message([] { from_text("[erosion]\nnoise_amplitude = 1.5\n"); });
  EXPECT_NE(msg.find("'erosion.noise_amplitude'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("in [0, 1]"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[erosion]\nnoise_scale = 0\n"); });
  EXPECT_NE(msg.find("'erosion.noise_scale'"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[erosion]\nnoise_scale = \"3 s\"\n"); });
  EXPECT_NE(msg.find("'erosion.noise_scale'"), std::string::npos) << msg;
  msg = config_error_message([] { from_text("[erosion]\nnoise_octaves = 17\n"); });
  EXPECT_NE(msg.find("'erosion.noise_octaves': expected an integer in [1, 16]"), std::string::npos)
      << msg;
  msg = config_error_message([] { from_text("[erosion]\nnoise_seed = 1.5\n"); });
  EXPECT_NE(msg.find("'erosion.noise_seed'"), std::string::npos) << msg;
  // Round trip through dump_toml.
  p = valid_params();
  p.erosion.hardness_noise = true;
  p.erosion.noise_scale = 250.0;
  const std::string text = erodem::dump_toml(p);
  EXPECT_NE(text.find("hardness = \"noise\""), std::string::npos) << text;
  const Params back = erodem::params_from_toml(toml::parse(text), "dump");
  EXPECT_TRUE(erodem::params_equal(p, back)) << text;
  EXPECT_TRUE(back.erosion.hardness_noise);
  EXPECT_NO_THROW(erodem::validate(back));
}

// ---- --set ------------------------------------------------------------------------------

TEST(Set, BareStringNumberAndArray) {
  Params p = valid_params();
  erodem::apply_setting(p, "flow.scheme", "pipes");
  EXPECT_EQ(p.flow.scheme, erodem::FlowScheme::pipes);
  erodem::apply_setting(p, "flow.scheme=\"local_inertial\"");
  EXPECT_EQ(p.flow.scheme, erodem::FlowScheme::local_inertial);
  erodem::apply_setting(p, "time.dt", "0.01");
  EXPECT_EQ(p.time.dt, 0.01);
  erodem::apply_setting(p, "rain.rate", "20 mm/h");
  EXPECT_NEAR(p.rain.rate, 0.02 / 3600.0, 1e-18) << p.rain.rate;
  erodem::apply_setting(p, "output.gauges", "[[1.0, 2.0], [3, 4]]");
  ASSERT_EQ(p.output.gauges.size(), 2u);
  EXPECT_EQ(p.output.gauges[1][1], 4.0);
  erodem::apply_setting(p, "dem.path=my dem.tif");
  EXPECT_EQ(p.dem.path, "my dem.tif");
  erodem::apply_setting(p, "time.adaptive=true");
  EXPECT_TRUE(p.time.adaptive);
  erodem::apply_setting(p, "inflow=[{point = [1, 2], hydrograph = [[0, 5]]}]");
  ASSERT_EQ(p.inflow.size(), 1u);
  EXPECT_EQ(p.inflow[0].hydrograph[0].value, 5.0);
  erodem::apply_setting(p, "erosion.bedrock_level=-3");
  EXPECT_EQ(p.erosion.bedrock_level, -3.0);
  erodem::apply_setting(p, "erosion.bedrock_level=none");
  EXPECT_FALSE(p.erosion.bedrock_level.has_value());
  EXPECT_NO_THROW(erodem::validate(p));
}

TEST(Set, LastAlternativeWins) {
  Params p = valid_params();
  erodem::apply_setting(p, "time.duration", "6 h");
  EXPECT_EQ(p.time.duration, 21600.0);
  erodem::apply_setting(p, "time.steps", "50");
  EXPECT_EQ(p.time.steps, 50);
  EXPECT_EQ(p.time.duration, 0.0);
  erodem::apply_setting(p, "rain.series", "[[0, 1e-6], [10, 0]]");
  erodem::apply_setting(p, "rain.rate", "1e-6");
  EXPECT_TRUE(p.rain.series.empty());
}

TEST(Set, ErrorsStartWithSet) {
  Params p = valid_params();
  std::string msg = config_error_message([&] { erodem::apply_setting(p, "flow.shceme", "pipes"); });
  EXPECT_EQ(msg.rfind("--set: 'flow.shceme': unknown parameter", 0), 0u) << msg;
  EXPECT_NE(msg.find("did you mean 'flow.scheme'"), std::string::npos) << msg;
  msg = config_error_message([&] { erodem::apply_setting(p, "rain.rate", "-1"); });
  EXPECT_EQ(msg.rfind("--set: 'rain.rate': expected a rate in [0, 1]", 0), 0u) << msg;
  msg = config_error_message([&] { erodem::apply_setting(p, "rain.rate"); });
  EXPECT_EQ(msg.rfind("--set: expected key=value", 0), 0u) << msg;
}

// ---- validate ---------------------------------------------------------------------------

TEST(Validate, CrossFieldChecks) {
  Params p;
  std::string msg = config_error_message([&] { erodem::validate(p); });
  EXPECT_NE(msg.find("'dem.path'"), std::string::npos) << msg;
  p = valid_params();
  EXPECT_NO_THROW(erodem::validate(p));
  p.time.cfl = std::nan("");
  msg = config_error_message([&] { erodem::validate(p); });
  EXPECT_NE(msg.find("'time.cfl'"), std::string::npos) << msg;
  p = valid_params();
  p.flow.theta = 1.5;
  msg = config_error_message([&] { erodem::validate(p, "x.toml"); });
  EXPECT_EQ(msg.rfind("x.toml: 'flow.theta': expected a number in [0, 1]", 0), 0u) << msg;
  p = valid_params();
  p.output.every = 0;
  EXPECT_THROW(erodem::validate(p), Error);
  p = valid_params();
  p.rain.series = {{0, 1e-6}, {0, 0}};
  msg = config_error_message([&] { erodem::validate(p); });
  EXPECT_NE(msg.find("times must increase"), std::string::npos) << msg;
  p = valid_params();
  p.dem.synthetic = "hill";
  EXPECT_THROW(erodem::validate(p), Error);
  p.dem.path.clear();
  EXPECT_NO_THROW(erodem::validate(p));
  p.output.fields.push_back("bed");
  EXPECT_THROW(erodem::validate(p), Error);
  // flow.order: 1 or 2, and 2 only with the shallow-water scheme
  p = valid_params();
  p.flow.order = 3;
  msg = config_error_message([&] { erodem::validate(p, "x.toml"); });
  EXPECT_EQ(msg.rfind("x.toml: 'flow.order': expected an integer in [1, 2]", 0), 0u) << msg;
  p.flow.order = 2;
  msg = config_error_message([&] { erodem::validate(p, "x.toml"); });
  EXPECT_NE(msg.find("'flow.order': order 2 is the shallow_water scheme's"), std::string::npos)
      << msg;
  p.flow.scheme = erodem::FlowScheme::shallow_water;
  EXPECT_NO_THROW(erodem::validate(p));
}

TEST(Units, DensityUnits) {
  // flow.water_density (the bed shear stress): kg/m^3 or g/cm^3, and no other dimension
  expect_quantity("1000 kg/m^3", Dimension::density, 1000.0);
  expect_quantity("1.025 g/cm^3", Dimension::density, 1025.0);
  const std::string msg =
      config_error_message([] { from_text("[flow]\nwater_density = \"1 m\"\n"); });
  EXPECT_NE(msg.find("'flow.water_density'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("kg/m^3, g/cm^3"), std::string::npos) << msg;
  EXPECT_EQ(from_text("[flow]\nwater_density = \"1 g/cm^3\"\n").flow.water_density, 1000.0);
}

// ---- dump -------------------------------------------------------------------------------

TEST(Dump, DefaultsRoundTrip) {
  const Params p;
  const std::string text = erodem::dump_toml(p);
  const Params back = erodem::params_from_toml(toml::parse(text), "dump");
  EXPECT_TRUE(erodem::params_equal(p, back)) << text;
  for (const std::string& key : erodem::parameter_keys()) {
    if (key == "inflow" || key == "section" || key == "outlet") continue;  // arrays of tables
    const std::string leaf = key.substr(key.rfind('.') + 1);
    EXPECT_NE(text.find(leaf + " = "), std::string::npos) << key;
    EXPECT_NE(text.find("# " + erodem::parameter_doc(key)), std::string::npos) << key;
  }
}

TEST(Dump, ModifiedRoundTrip) {
  Params p = valid_params();
  p.dem.window = std::array<int, 4>{1, 2, 30, 40};
  p.dem.resample_factor = 3;
  p.initial.water_level = 12.25;
  p.time.dt = 0.1 / 3.0;
  p.flow.scheme = erodem::FlowScheme::pipes;
  p.flow.manning_n.path = "n \"quoted\".tif";
  p.flow.pipe_length = 7.5;
  p.rain.series = {{0, 0}, {600, 0.04 / 3600}, {3600, 0}};
  p.inflow = {{{{0.0, 990.0}, {0.0, 1010.0}}, {{0, 0}, {3000, 20}}}, {{{5.0, 6.0}}, {{0, 1.5}}}};
  p.erosion.bedrock_level = -1e-7;
  p.erosion.hardness.value = 0.3;
  p.boundary.west = erodem::BoundaryKind::fixed_level;
  p.output.fields = {"bed", "flux_left"};
  p.output.gauges = {{1.0, 2.0}};
  p.numerics.precision = erodem::Precision::float64;
  p.numerics.threads = 4;
  p.snow.temperature_grids = "NETCDF:\"t2m.nc\":t2m";
  p.snow.temperature_grid_times = {0.0, 600.0, 7200.0 / 7.0};
  const std::string text = erodem::dump_toml(p);
  Params back;
  ASSERT_NO_THROW(back = erodem::params_from_toml(toml::parse(text), "dump")) << text;
  EXPECT_TRUE(erodem::params_equal(p, back)) << text << "\n---\n" << erodem::dump_toml(back);
  EXPECT_EQ(back.time.dt, p.time.dt);
  EXPECT_EQ(back.flow.manning_n.path, p.flow.manning_n.path);
  ASSERT_EQ(back.inflow.size(), 2u);
  EXPECT_EQ(back.inflow[1].vertices.size(), 1u);
  EXPECT_EQ(back.rain.series[1].value, p.rain.series[1].value);
  EXPECT_EQ(back.snow.temperature_grids, p.snow.temperature_grids);
  EXPECT_EQ(back.snow.temperature_grid_times, p.snow.temperature_grid_times);
  EXPECT_EQ(back.dem.window, p.dem.window);
  EXPECT_EQ(back.erosion.bedrock_level, p.erosion.bedrock_level);
  EXPECT_NO_THROW(erodem::validate(back));
}

TEST(Dump, ParamsEqualDetectsDifference) {
  Params a;
  Params b;
  b.thermal.rate = std::nextafter(a.thermal.rate, 1.0);
  EXPECT_FALSE(erodem::params_equal(a, b));
}

// ---- keys and docs ----------------------------------------------------------------------

TEST(Keys, EveryKeyHasDocWithUnitAndDefault) {
  const auto keys = erodem::parameter_keys();
  EXPECT_GE(keys.size(), 55u) << keys.size();
  for (const std::string& key : keys) {
    const erodem::ParameterInfo info = erodem::parameter_info(key);
    EXPECT_FALSE(info.doc.empty()) << key;
    EXPECT_FALSE(info.default_value.empty()) << key;
    if (!info.unit.empty()) {
      EXPECT_NE(info.doc.find("(" + info.unit), std::string::npos) << key << ": " << info.doc;
    }
  }
  EXPECT_EQ(erodem::parameter_info("time.dt").default_value, "0.05");
  EXPECT_EQ(erodem::parameter_info("rain.rate").unit, "m/s");
  EXPECT_THROW(erodem::parameter_doc("nope"), Error);
}

// ---- config files -----------------------------------------------------------------------

TEST(ConfigFile, MissingFileExitCode66) {
  try {
    erodem::load_config("/nonexistent/erodem/config.toml");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), 66);
    EXPECT_EQ(std::string(e.what()), "/nonexistent/erodem/config.toml: no such config file");
  }
}

TEST(ConfigFile, SyntaxErrorExitCode78WithLine) {
  const std::string path = write_temp("bad.toml", "[time]\ndt = 0.1\nsteps = = 3\n");
  try {
    erodem::load_config(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), 78);
    EXPECT_EQ(std::string(e.what()).rfind(path + ":3:", 0), 0u) << e.what();
  }
}

TEST(ConfigFile, UnknownKeyNamesFile) {
  const std::string path = write_temp("unknown.toml", "[flow]\nmannings_n = 0.03\n");
  try {
    erodem::load_config(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), 78);
    EXPECT_EQ(std::string(e.what()).rfind(path + ": 'flow.mannings_n': unknown parameter", 0), 0u)
        << e.what();
  }
}

TEST(ConfigFile, RelativePathsResolvedAgainstConfigDir) {
  const std::string path =
      write_temp("paths.toml",
                 "[dem]\npath = \"sub/dem.tif\"\n[erosion]\nhardness = \"/abs/h.tif\"\n"
                 "[flow]\nmanning_n = \"n.tif\"\n[output]\npath = \"out.h5\"\n");
  const Params p = erodem::load_config(path);
  const auto dir = std::filesystem::path(path).parent_path();
  EXPECT_EQ(p.dem.path, (dir / "sub/dem.tif").string());
  EXPECT_EQ(p.flow.manning_n.path, (dir / "n.tif").string());
  EXPECT_EQ(p.erosion.hardness.path, "/abs/h.tif");
  EXPECT_EQ(p.output.path, "out.h5");
  EXPECT_NO_THROW(erodem::validate(p));
}

}  // namespace
