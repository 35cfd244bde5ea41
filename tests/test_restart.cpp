// erodem — restart: a run continued from any stored time of its result file reproduces the
// uninterrupted run bit for bit (same backend and precision), and bad restarts are clear
// errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "cli_runner.hpp"
#include "erodem/backends.hpp"
#include "erodem/io/results.hpp"
#include "erodem/simulation.hpp"

namespace fs = std::filesystem;

namespace {

using erodem::test::run_cli;

/// Local inertial flow, conservative transport, thermal collapse, a snow pack above 20 m (a
/// temperature series through the snowfall threshold, sliding), Green-Ampt infiltration into a
/// finite store, an open and a fixed-level edge, a rain series and adaptive steps: every state
/// field changes.
const char* kInertial = R"([dem]
synthetic = "valley"
size = 48
seed = 3
relief = "40 m"
cell_size = "10 m"
[initial]
water_depth = 0.05
[time]
duration = "8 min"
adaptive = true
cfl = 0.7
dt_max = "2 s"
[flow]
scheme = "local_inertial"
manning_n = 0.035
[rain]
series = [[0, "80 mm/h"], [200, "20 mm/h"]]
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.2
dissolving_rate = 0.01
deposition_rate = 0.05
[thermal]
enabled = true
talus_angle = 30.0
rate = 0.05
[evaporation]
rate = 1e-6
[snow]
enabled = true
initial = "20 mm"
snow_line = "20 m"
transition = "10 m"
slide_angle = 20.0
slide_rate = 0.01
air_temperature = [[0, -2.0], [480, 6.0]]
melt_factor = "100 mm/d"
[infiltration]
enabled = true
ksat = "10 mm/h"
soil_depth = "5 cm"
[boundary]
east = "open"
west = "fixed_level"
sea_level = 1.0
[output]
path = "full.h5"
interval = "2 min"
fields = ["bed", "water_depth", "sediment", "velocity_x", "velocity_y", "erosion", "wetness",
          "snow", "snow_liquid", "infiltrated"]
)";

/// The same with the shallow-water scheme: its unit discharges are state too.
const std::string kShallowWater = [] {
  std::string c = kInertial;
  const std::string from = "scheme = \"local_inertial\"";
  c.replace(c.find(from), from.size(), "scheme = \"shallow_water\"");
  return c;
}();

/// The same with the shallow-water scheme's second order (Heun's two stages in one step).
const std::string kShallowWater2 = [] {
  std::string c = kShallowWater;
  const std::string from = "scheme = \"shallow_water\"";
  c.replace(c.find(from), from.size(), "scheme = \"shallow_water\"\norder = 2");
  return c;
}();

/// The same with the physical erosion law (its soil thickness is state too), over a thin soil
/// so that some of the bedrock erodes.
const std::string kPhysical = [] {
  std::string c = kInertial;
  const std::string from = "law = \"mei\"";
  c.replace(c.find(from), from.size(),
            "law = \"physical\"\nsoil_thickness = \"2 mm\"\ngrain_size = \"0.2 mm\"\n"
            "bedrock.erosion_rate = 1e-3\nbedrock.critical_shear = \"0.5 Pa\"");
  return c;
}();

/// The same with terrain classes every 7 steps, whose tables give Manning n, talus angles and
/// K_sat by class: a restart between two classifications writes the tables again from the
/// classes it restores.
const std::string kClasses = std::string(kInertial) + R"(
[terrain_classes]
enabled = true
interval = 7
rock_slope = 0.2
mud_wetness = "2 mm"
water_wetness = "2 cm"
grass.manning_n = 0.045
rock.manning_n = 0.03
rock.talus_angle = 40.0
mud.talus_angle = 20.0
mud.ksat = "2 mm/h"
snow.manning_n = 0.02
)";

/// Pipes, semi-Lagrangian transport, a point inflow hydrograph and fixed steps.
const char* kPipes = R"([dem]
synthetic = "hill"
size = 40
seed = 5
relief = "20 m"
cell_size = "5 m"
[time]
steps = 150
dt = 0.1
[flow]
scheme = "pipes"
[rain]
rate = "30 mm/h"
[[inflow]]
point = [60.0, 140.0]
hydrograph = [[0, 0.0], [5, 2.0], [15, 0.5]]
[erosion]
law = "mei"
enabled = true
sediment_capacity = 0.5
dissolving_rate = 0.05
deposition_rate = 0.1
[transport]
scheme = "semi_lagrangian"
[boundary]
south = "open"
[output]
path = "full.h5"
every = 50
fields = ["bed", "water_depth", "sediment", "erosion", "flux_left", "flux_top"]
)";

struct Case {
  const char* name;
  const char* config;
  const char* backend;    // --backend
  const char* precision;  // numerics.precision
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name << "_" << c.backend << "_" << c.precision;
}

class Restart : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    if (std::string(GetParam().backend) == "opencl" && !erodem::opencl_available())
      GTEST_SKIP() << "no OpenCL device";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->name());
    for (char& ch : name)
      if (ch == '/') ch = '_';
    // the process id too: two test programs running this case at once (two build trees on
    // one machine) must not remove each other's files
    dir_ =
        fs::temp_directory_path() / ("erodem_restart_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "config.toml") << GetParam().config;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string run_args(const std::string& extra) const {
    return std::string("run config.toml --backend ") + GetParam().backend +
           " --set numerics.precision=" + GetParam().precision + " " + extra;
  }
  fs::path dir_;
};

/// Exact equality of two float fields, NaN (nodata) equal to NaN; returns the cells that
/// differ.
std::size_t differing(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) ++n;
  return n;
}

std::size_t differing(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0) ++n;
  return n;
}

TEST_P(Restart, FromEveryStoredTimeReproducesTheRunBitForBit) {
  const auto full = run_cli(run_args("--output full.h5"), dir_);
  ASSERT_EQ(full.code, 0) << full.output;
  const erodem::io::ResultReader a((dir_ / "full.h5").string());
  ASSERT_TRUE(a.has_restart_state());
  const auto times = a.times();
  ASSERT_GE(times.size(), 4u);
  const auto diag_a = a.diagnostics();
  const auto fields = a.fields();

  // From the first snapshot after t = 0 and from the one before the last.
  for (std::size_t from : {std::size_t{1}, times.size() - 2}) {
    const std::string out = "restart_" + std::to_string(from) + ".h5";
    const auto r = run_cli(
        run_args("--output " + out + " --restart full.h5:" + std::to_string(times[from])), dir_);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(r.output.find("differs"), std::string::npos) << r.output;
    const erodem::io::ResultReader b((dir_ / out).string());
    ASSERT_EQ(b.times().size(), times.size() - from);
    EXPECT_NE(b.attribute("restart_from").find("full.h5:"), std::string::npos);
    std::size_t cells_compared = 0, cells_differing = 0;
    for (std::size_t j = 0; j < b.times().size(); ++j) {
      const std::size_t i = from + j;
      ASSERT_EQ(b.times()[j], times[i]) << "snapshot " << j;
      for (const auto& f : fields) {
        const auto va = a.read_index(f, i), vb = b.read_index(f, j);
        cells_compared += va.size();
        cells_differing += differing(va, vb);
      }
      const auto pa = a.restart_point(i), pb = b.restart_point(j);
      EXPECT_EQ(pa.steps, pb.steps);
      EXPECT_EQ(std::memcmp(&pa.ledger, &pb.ledger, sizeof pa.ledger), 0) << "ledger at " << i;
      for (std::size_t k = 0; k < pa.fields.size(); ++k) {
        cells_compared += pa.fields[k].size();
        cells_differing += differing(pa.fields[k], pb.fields[k]);
      }
    }
    // The diagnostics of every step after the restart.
    const auto diag_b = b.diagnostics();
    const auto steps_from = static_cast<std::size_t>(a.restart_point(from).steps);
    ASSERT_EQ(diag_b.size(), diag_a.size() - steps_from);
    std::size_t diag_differing = 0;
    for (std::size_t s = 0; s < diag_b.size(); ++s)
      if (std::memcmp(&diag_a[steps_from + s], &diag_b[s], sizeof(erodem::Diagnostics)) != 0)
        ++diag_differing;
    std::printf(
        "[restart] %s from t = %.6g s (step %zu): %zu of %zu stored values differ, %zu of "
        "%zu diagnostics rows differ (bound: 0)\n",
        ::testing::PrintToString(GetParam()).c_str(), times[from], steps_from, cells_differing,
        cells_compared, diag_differing, diag_b.size());
    EXPECT_EQ(cells_differing, 0u);
    EXPECT_EQ(diag_differing, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Runs, Restart,
    ::testing::Values(Case{"inertial", kInertial, "cpu", "float32"},
                      Case{"inertial", kInertial, "cpu", "float64"},
                      Case{"inertial", kInertial, "opencl", "float32"},
                      Case{"shallow_water", kShallowWater.c_str(), "cpu", "float32"},
                      Case{"shallow_water", kShallowWater.c_str(), "cpu", "float64"},
                      Case{"shallow_water", kShallowWater.c_str(), "opencl", "float32"},
                      Case{"shallow_water_order2", kShallowWater2.c_str(), "cpu", "float32"},
                      Case{"shallow_water_order2", kShallowWater2.c_str(), "cpu", "float64"},
                      Case{"shallow_water_order2", kShallowWater2.c_str(), "opencl", "float32"},
                      Case{"physical", kPhysical.c_str(), "cpu", "float32"},
                      Case{"physical", kPhysical.c_str(), "cpu", "float64"},
                      Case{"physical", kPhysical.c_str(), "opencl", "float32"},
                      Case{"classes", kClasses.c_str(), "cpu", "float32"},
                      Case{"classes", kClasses.c_str(), "cpu", "float64"},
                      Case{"classes", kClasses.c_str(), "opencl", "float32"},
                      Case{"pipes", kPipes, "cpu", "float32"},
                      Case{"pipes", kPipes, "opencl", "float32"}),
    [](const ::testing::TestParamInfo<Case>& p) {
      return std::string(p.param.name) + "_" + p.param.backend + "_" + p.param.precision;
    });

class RestartErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("erodem_restart_errors_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "config.toml") << kPipes;
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(RestartErrors, ClearMessagesAndExitCodes) {
  const std::string run = "run config.toml --backend cpu ";
  for (const char* out : {"a.h5", "plain.h5"}) {
    const std::string extra =
        std::string(out) == "plain.h5" ? "--set output.restart_state=false " : "";
    ASSERT_EQ(
        run_cli(run + "--set time.steps=20 --set output.every=10 " + extra + "--output " + out,
                dir_)
            .code,
        0);
  }
  struct Expect {
    const char* what;
    const char* args;
    int code;
    const char* message;
  };
  for (const Expect& e : {
           Expect{"a time not stored (the stored ones are listed)",
                  "--output b.h5 --restart a.h5:0.55", 2,
                  "the file holds the state at t = 0, 1, 2 s (3 times)"},
           Expect{"a missing file", "--output b.h5 --restart nothere.h5", 66, "nothere.h5"},
           Expect{"no restart state", "--output b.h5 --restart plain.h5", 65, "no restart state"},
           Expect{"another grid", "--set dem.size=32 --output b.h5 --restart a.h5", 65, "40 x 40"},
           // A changed parameter is allowed, with a warning naming it; the last time is the
           // default.
           Expect{"a changed parameter",
                  "--set time.steps=30 --set erosion.dissolving_rate=0.2 --output c.h5 --restart "
                  "a.h5",
                  0, "erosion.dissolving_rate"},
       }) {
    const auto r = run_cli(run + e.args, dir_);
    std::printf("  [%s] exit %d (expected %d): %s", e.what, r.code, e.code, r.output.c_str());
    EXPECT_EQ(r.code, e.code) << e.what << ": " << r.output;
    EXPECT_NE(r.output.find(e.message), std::string::npos) << e.what << ": " << r.output;
  }
  EXPECT_EQ(erodem::io::ResultReader((dir_ / "c.h5").string()).restart_point(0).steps, 20);
  // Nothing left behind by the failed runs.
  EXPECT_FALSE(fs::exists(dir_ / "b.h5"));
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_NE(e.path().filename().string().rfind(".b.h5.", 0), 0u) << e.path();
}

TEST_F(RestartErrors, RestartEveryStoresEveryNthStateAndTheLast) {
  // Snapshots at steps 0, 10, 20, 30, 40 and 45; the state at the 1st, 4th and the last.
  const std::string run =
      "run config.toml --backend cpu --set time.steps=45 --set output.every=10 ";
  ASSERT_EQ(run_cli(run + "--output every1.h5", dir_).code, 0);
  const auto r = run_cli(run + "--set output.restart_every=3 --output every3.h5", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("MB per snapshot with the restart state at 3 of them)"),
            std::string::npos)
      << r.output;
  const erodem::io::ResultReader all((dir_ / "every1.h5").string()),
      some((dir_ / "every3.h5").string());
  ASSERT_EQ(some.times().size(), 6u);
  const auto& t = some.times();
  EXPECT_EQ(some.restart_times(), (std::vector<double>{t[0], t[3], t[5]}));
  EXPECT_EQ(all.restart_times(), t);
  // The same states as the file with all of them; the once-per-value fields (initial_bed,
  // which no sweep writes) in one row.
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{3, 1}, std::pair{5, 2}}) {
    const auto pa = all.restart_point(i), pb = some.restart_point(j);
    EXPECT_EQ(pa.steps, pb.steps);
    EXPECT_EQ(std::memcmp(&pa.ledger, &pb.ledger, sizeof pa.ledger), 0);
    ASSERT_EQ(pa.fields.size(), pb.fields.size());
    for (std::size_t k = 0; k < pa.fields.size(); ++k)
      EXPECT_EQ(differing(pa.fields[k], pb.fields[k]), 0u) << k;
  }
  const auto sizes =
      std::pair{fs::file_size(dir_ / "every1.h5"), fs::file_size(dir_ / "every3.h5")};
  std::printf("[restart_every] 6 snapshots: %ju bytes with the state at each, %ju at 3 of them\n",
              static_cast<std::uintmax_t>(sizes.first), static_cast<std::uintmax_t>(sizes.second));
  EXPECT_LT(sizes.second, sizes.first);
  // From a stored state: the run goes on as the full one did, bit for bit.
  const auto from =
      run_cli(run + "--output from.h5 --restart every3.h5:" + std::to_string(t[3]), dir_);
  ASSERT_EQ(from.code, 0) << from.output;
  const erodem::io::ResultReader b((dir_ / "from.h5").string());
  ASSERT_EQ(b.times().size(), 3u);
  for (std::size_t j = 0; j < 3; ++j)
    for (const auto& f : all.fields())
      EXPECT_EQ(differing(all.read_index(f, 3 + j), b.read_index(f, j)), 0u) << f << " " << j;
  // A snapshot without its state, and a bad value.
  for (const auto& [args, code, message] :
       {std::tuple{"--output c.h5 --restart every3.h5:" + std::to_string(t[1]), 2,
                   std::string("that snapshot has no stored state (output.restart_every); the "
                               "file holds the state at t = 0, ")},
        std::tuple{std::string("--set output.restart_every=0 --output c.h5"), 78,
                   std::string("output.restart_every")}}) {
    const auto e = run_cli(run + args, dir_);
    std::printf("  exit %d: %s", e.code, e.output.c_str());
    EXPECT_EQ(e.code, code) << e.output;
    EXPECT_NE(e.output.find(message), std::string::npos) << e.output;
    if (code == 2) {
      EXPECT_NE(e.output.find("(3 times)"), std::string::npos) << e.output;
    }
  }
  EXPECT_FALSE(fs::exists(dir_ / "c.h5"));
}

}  // namespace
