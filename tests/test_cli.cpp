// erodem — the command line end to end: exit codes, messages, no partial output.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_runner.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/results.hpp"

namespace fs = std::filesystem;

namespace {

using erodem::test::CliResult;
using erodem::test::run_cli;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("erodem_cli_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
  }
  std::size_t files_matching(const std::string& prefix) const {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
    return n;
  }
  /// The partial file of result `name` (".NAME.HOST-PID.partial"); empty when there is none.
  fs::path partial_of(const std::string& name) const {
    const std::string prefix = "." + name + ".";
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string f = e.path().filename().string();
      if (f.rfind(prefix, 0) == 0 && f.size() > 8 && f.substr(f.size() - 8) == ".partial")
        return e.path();
    }
    return {};
  }
  fs::path dir_;
};

const char* kConfig = R"([dem]
path = "hill.tif"
[initial]
water_depth = 0.0
[time]
steps = 200
dt = 0.5
[rain]
rate = "100 mm/h"
[erosion]
law = "mei"
enabled = true
[boundary]
east = "open"
[output]
path = "out.h5"
fields = ["bed", "water_depth", "erosion"]
)";

TEST_F(Cli, GenerateIsReproducible) {
  auto a = run_cli("generate --kind fbm --size 64 --seed 3 a.tif", dir_);
  auto b = run_cli("generate --kind fbm --size 64 --seed 3 b.tif", dir_);
  auto c = run_cli("generate --kind fbm --size 64 --seed 4 c.tif", dir_);
  ASSERT_EQ(a.code, 0) << a.output;
  ASSERT_EQ(b.code, 0) << b.output;
  ASSERT_EQ(c.code, 0) << c.output;
  erodem::Params::Dem d;
  d.path = (dir_ / "a.tif").string();
  const auto ta = erodem::io::read_dem(d);
  d.path = (dir_ / "b.tif").string();
  const auto tb = erodem::io::read_dem(d);
  d.path = (dir_ / "c.tif").string();
  const auto tc = erodem::io::read_dem(d);
  EXPECT_EQ(ta.grid.nx, 64);
  EXPECT_EQ(ta.bed, tb.bed);
  EXPECT_NE(ta.bed, tc.bed);
  // An existing file is not overwritten.
  const auto again = run_cli("generate --kind hill --size 32 a.tif", dir_);
  EXPECT_EQ(again.code, 73) << again.output;
  d.path = (dir_ / "a.tif").string();
  EXPECT_EQ(erodem::io::read_dem(d).bed, ta.bed);
}

TEST_F(Cli, RunWritesFieldsAndPrintsLedger) {
  ASSERT_EQ(run_cli("generate --kind hill --size 48 --relief 30 hill.tif", dir_).code, 0);
  write("c.toml", kConfig);
  const auto r = run_cli("run c.toml", dir_);
  std::printf("%s", r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("mass ledger"), std::string::npos);
  EXPECT_NE(r.output.find("closure"), std::string::npos);
  EXPECT_NE(r.output.find("wrote out.h5"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "out.xmf"));
  EXPECT_TRUE(partial_of("out.h5").empty());
  {
    const erodem::io::ResultReader out((dir_ / "out.h5").string());
    EXPECT_EQ(out.times().size(), 3u);  // steps 0, 100 (output.every) and 200
    EXPECT_EQ(out.diagnostics().size(), 200u);
    EXPECT_EQ(out.fields(), (std::vector<std::string>{"bed", "water_depth", "erosion"}));
  }
  // A second run refuses to overwrite, and leaves the file as it was.
  const auto before = fs::last_write_time(dir_ / "out.h5");
  const auto again = run_cli("run c.toml", dir_);
  EXPECT_EQ(again.code, 73) << again.output;
  EXPECT_NE(again.output.find("--overwrite"), std::string::npos);
  EXPECT_EQ(fs::last_write_time(dir_ / "out.h5"), before);
  EXPECT_EQ(run_cli("run c.toml --overwrite --set time.steps=3", dir_).code, 0);
}

TEST_F(Cli, ExportWritesAStoredFieldAsGeoTiff) {
  ASSERT_EQ(run_cli("generate --kind hill --size 48 --relief 30 hill.tif", dir_).code, 0);
  write("c.toml", kConfig);
  ASSERT_EQ(run_cli("run c.toml", dir_).code, 0);
  const auto r = run_cli("export out.h5 --field water_depth --time 50 depth50.tif", dir_);
  std::printf("[export] exit %d: %s", r.code, r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  const erodem::io::ResultReader run((dir_ / "out.h5").string());
  erodem::Params::Dem d;
  d.path = (dir_ / "depth50.tif").string();
  const auto tif = erodem::io::read_dem(d);
  const auto stored = run.read_index("water_depth", run.nearest_time_index(50.0));
  ASSERT_EQ(tif.bed.size(), stored.size());
  double worst = 0;
  for (std::size_t i = 0; i < stored.size(); ++i)
    worst = std::max(worst, std::abs(tif.bed[i] - static_cast<double>(stored[i])));
  EXPECT_EQ(worst, 0.0) << "the GeoTIFF holds the stored float32 values";
  EXPECT_EQ(tif.grid.georef.transform, run.grid().georef.transform);
  // A time or field the file does not hold is a clear error, and nothing is written.
  const auto no_time = run_cli("export out.h5 --field water_depth --time 42 x.tif", dir_);
  std::printf("[export] %s", no_time.output.c_str());
  EXPECT_EQ(no_time.code, 65);
  EXPECT_NE(no_time.output.find("stored: 0, 50, 100"), std::string::npos) << no_time.output;
  const auto no_field = run_cli("export out.h5 --field sediment x.tif", dir_);
  EXPECT_EQ(no_field.code, 65);
  EXPECT_NE(no_field.output.find("'sediment'"), std::string::npos) << no_field.output;
  EXPECT_FALSE(fs::exists(dir_ / "x.tif"));
  EXPECT_EQ(run_cli("export nowhere.h5 --field bed x.tif", dir_).code, 66);
}

TEST_F(Cli, BadConfigValuesExit78WithoutOutput) {
  ASSERT_EQ(run_cli("generate --kind hill --size 16 hill.tif", dir_).code, 0);
  struct Case {
    const char* what;
    std::string config;
    const char* args;
    const char* must_name;
  };
  const Case cases[] = {
      {"negative rain", std::string(kConfig) + "", "--set rain.rate=-5", "rain.rate"},
      {"unknown key", std::string(kConfig) + "[thermal]\ntalus = 30\n", "", "thermal.talus"},
      {"bad scheme", kConfig, "--set flow.scheme=upwind", "flow.scheme"},
      {"negative capacity", kConfig, "--set erosion.sediment_capacity=-1",
       "erosion.sediment_capacity"},
      {"bad unit", kConfig, "--set 'rain.rate=20 kg'", "rain.rate"},
      // finite but absurd: no rain reaches 1 m/s (it made the depth infinite at step 1)
      {"absurd rain", kConfig, "--set rain.rate=1e300", "rain.rate"},
      // a wrong unit on a key that also takes a raster path is a unit error, not a file
      {"unit on a raster key", kConfig, "--set 'flow.manning_n=0.03 s m-1/3'", "flow.manning_n"},
      {"decimal comma on a raster key", kConfig, "--set 'flow.manning_n=0,03'", "flow.manning_n"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    write("bad.toml", c.config);
    const auto r = run_cli(std::string("run bad.toml ") + c.args, dir_);
    std::printf("[bad config] %s -> exit %d: %s", c.what, r.code, r.output.c_str());
    EXPECT_EQ(r.code, 78);
    EXPECT_NE(r.output.find(c.must_name), std::string::npos) << r.output;
    EXPECT_EQ(files_matching("out"), 0u);
    EXPECT_EQ(files_matching(".out"), 0u);
  }
}

/// The lines of `text` (the last one without a newline counts too).
std::size_t lines(const std::string& text) {
  std::size_t n = 0;
  for (char ch : text) n += ch == '\n';
  return n + (!text.empty() && text.back() != '\n');
}

TEST_F(Cli, UsageAndInputErrorsAreOneLineWithTheirCodes) {
  // Each of these was seen to print two lines without the "erodem:" prefix, HDF5's error
  // page, the wrong code, or nothing at all (issue 19).
  ASSERT_EQ(run_cli("generate --kind hill --size 16 hill.tif", dir_).code, 0);
  write("c.toml", kConfig);
  struct Case {
    const char* what;
    std::string args;
    int code;
    const char* must_name;
  };
  // a result file whose metadata is corrupt (bytes 2000-4000 flipped)
  ASSERT_EQ(run_cli("run c.toml --set time.steps=4 --output good.h5", dir_).code, 0);
  {
    std::ifstream in(dir_ / "good.h5", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (std::size_t k = 2000; k < 4000 && k < bytes.size(); ++k) bytes[k] ^= 0x5A;
    std::ofstream(dir_ / "bad.h5", std::ios::binary) << bytes;
  }
  // an ASCII grid with a cell of -1e39 (a float stores -inf or -3.4e38)
  write("broken.asc",
        "ncols 4\nnrows 4\nxllcorner 0\nyllcorner 0\ncellsize 10\n"
        "1 2 3 4\n5 -1e39 7 8\n9 10 11 12\n13 14 15 16\n");
  std::string broken = kConfig;
  broken.replace(broken.find("hill.tif"), 8, "broken.asc");
  write("broken.toml", broken);
  fs::create_directories(dir_ / "folder.toml");
  const Case cases[] = {
      {"bad backend", "run c.toml --backend nope", 2, "--backend"},
      {"unknown option", "run c.toml --frobnicate", 2, "--frobnicate"},
      {"empty --output", "run c.toml --output ''", 2, "--output"},
      {"config is a folder", "run folder.toml", 74, "folder.toml"},
      {"corrupt result file", "compare bad.h5 good.h5", 65, "bad.h5"},
      {"corrupt restart file", "run c.toml --restart bad.h5 --output x.h5", 65, "bad.h5"},
      {"broken elevation", "run broken.toml --set dem.crs=EPSG:32610", 65, "cell (col 1, row 1)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = run_cli(c.args, dir_);
    std::printf("[one line] %s -> exit %d, %zu line(s): %s", c.what, r.code, lines(r.output),
                r.output.c_str());
    EXPECT_EQ(r.code, c.code);
    EXPECT_EQ(lines(r.output), 1u);
    EXPECT_EQ(r.output.rfind("erodem: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.must_name), std::string::npos) << r.output;
    EXPECT_EQ(files_matching("out"), 0u);
    EXPECT_EQ(files_matching("x.h5"), 0u);
  }
}

TEST_F(Cli, RestartedRunCountsOnlyItsOwnSteps) {
  // 200 steps with snapshots every 50; a restart from the snapshot at step 100 runs 100 steps
  // and says so (it said 200, and a cell-steps/s twice the true one).
  ASSERT_EQ(run_cli("generate --kind hill --size 16 hill.tif", dir_).code, 0);
  write("c.toml", std::string(kConfig) + "every = 50\n");
  ASSERT_EQ(run_cli("run c.toml", dir_).code, 0);
  const auto r = run_cli("run c.toml --restart out.h5:50 --output again.h5", dir_);
  std::printf("[restart steps] exit %d: %s", r.code, r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("ran 100 steps to t = 100 s"), std::string::npos) << r.output;
}

TEST_F(Cli, InfoDescribesAResultFile) {
  // `info` of a result file says what it holds (it read it as a DEM and failed before).
  ASSERT_EQ(run_cli("generate --kind hill --size 16 hill.tif", dir_).code, 0);
  write("c.toml", std::string(kConfig) + "every = 100\n");
  ASSERT_EQ(run_cli("run c.toml", dir_).code, 0);
  const auto r = run_cli("info out.h5", dir_);
  std::printf("[info result]\n%s", r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* want :
       {"result file  out.h5", "grid         16 x 16 cells",
        "fields       bed, water_depth, erosion", "snapshots    3: t = 0 .. 100 s",
        "--restart out.h5:TIME with TIME one of 0, 50, 100 s", "steps        200, to t = 100 s",
        "backend      "})
    EXPECT_NE(r.output.find(want), std::string::npos) << want;
  const auto j = run_cli("info out.h5 --json", dir_);
  ASSERT_EQ(j.code, 0) << j.output;
  EXPECT_NE(j.output.find("\"times_s\": [0, 50, 100]"), std::string::npos) << j.output;
  EXPECT_NE(j.output.find("\"restart_state\": true"), std::string::npos) << j.output;
  EXPECT_NE(j.output.find("\"steps\": 200"), std::string::npos) << j.output;
  EXPECT_NE(j.output.find("\"restart_times_s\": [0, 50, 100]"), std::string::npos) << j.output;
  // With the state at every other snapshot (and the last): the times that have it.
  ASSERT_EQ(run_cli("run c.toml --set output.restart_every=2 --output some.h5", dir_).code, 0);
  const auto some = run_cli("info some.h5", dir_);
  EXPECT_NE(some.output.find("the full state at 2 of the 3 snapshots: erodem run CONFIG "
                             "--restart some.h5:TIME with TIME one of 0, 100 s"),
            std::string::npos)
      << some.output;
  EXPECT_NE(run_cli("info some.h5 --json", dir_).output.find("\"restart_times_s\": [0, 100]"),
            std::string::npos);
}

TEST_F(Cli, MissingFilesExit66) {
  auto r = run_cli("run nowhere.toml", dir_);
  std::printf("[missing config] exit %d: %s", r.code, r.output.c_str());
  EXPECT_EQ(r.code, 66);
  EXPECT_NE(r.output.find("nowhere.toml"), std::string::npos);
  write("c.toml", kConfig);  // refers to hill.tif, which does not exist
  r = run_cli("run c.toml", dir_);
  std::printf("[missing DEM] exit %d: %s", r.code, r.output.c_str());
  EXPECT_EQ(r.code, 66);
  EXPECT_NE(r.output.find("hill.tif"), std::string::npos);
  EXPECT_EQ(files_matching("out"), 0u);
  EXPECT_EQ(files_matching(".out"), 0u);
}

TEST_F(Cli, UnstableRunExit75NamesTheCell) {
  ASSERT_EQ(run_cli("generate --kind lake --size 32 --relief 20 hill.tif", dir_).code, 0);
  write("c.toml", kConfig);
  const auto r = run_cli("run c.toml --set initial.water_depth=5 --set time.dt=30", dir_);
  std::printf("[unstable] exit %d: %s", r.code, r.output.c_str());
  EXPECT_EQ(r.code, 75);
  EXPECT_NE(r.output.find("cell (col"), std::string::npos);
  // The final name is not created; the steps so far stay in the partial file.
  EXPECT_EQ(files_matching("out"), 0u);
  const fs::path partial = partial_of("out.h5");
  ASSERT_FALSE(partial.empty());
  EXPECT_NE(r.output.find(partial.filename().string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("was not created"), std::string::npos) << r.output;
  EXPECT_GE(erodem::io::ResultReader(partial.string()).times().size(), 1u);
}

TEST_F(Cli, DumpConfigRoundTripsAndUsageErrors) {
  write("c.toml", kConfig);
  const auto r = run_cli("run c.toml --set flow.scheme=pipes --dump-config", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("scheme = \"pipes\""), std::string::npos) << r.output;
  write("dumped.toml", r.output);
  const auto again = run_cli("run dumped.toml --dump-config", dir_);
  EXPECT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(again.output, r.output);
  EXPECT_EQ(run_cli("frobnicate", dir_).code, 2);
  EXPECT_EQ(run_cli("run", dir_).code, 2);
}

}  // namespace
