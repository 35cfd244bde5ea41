// erodem — DEM inputs end to end: every raster format the docs promise reads to the same
// elevations and georeferencing, and each kind of bad input is a one-line error with the
// documented exit code that leaves no output behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/params.hpp"

namespace fs = std::filesystem;
using erodem::test::run_cli;

namespace {

const std::string kShared = ERODEM_SHARED_DIR;
const std::string kVolcano = kShared + "/data/dem/volcano/volcano_northup_10m.tif";
const std::string kTujunga = kShared + "/data/dem/big_tujunga/srtm_bigtujunga30m_utm11.tif";
const std::string kDfw = kShared + "/data/dem/dfw/dfw_srtm3.tif";

class DemInputs : public ::testing::Test {
 public:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("erodem_dem_inputs_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  /// Runs a shell command in the test folder; returns its exit status.
  int sh(const std::string& cmd) const {
    return std::system(("cd '" + dir_.string() + "' && " + cmd + " >/dev/null 2>&1").c_str());
  }
  /// Files in the test folder whose name starts with `prefix` (also hidden .partial ones).
  std::size_t files_matching(const std::string& prefix) const {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const auto name = e.path().filename().string();
      if (name.rfind(prefix, 0) == 0 || name.rfind("." + prefix, 0) == 0) ++n;
    }
    return n;
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
  }
  fs::path dir_;
};

erodem::Terrain read(const std::string& path, const std::string& cell_size = "",
                     const std::string& crs = "") {
  erodem::Params::Dem dem;
  dem.path = path;
  if (!cell_size.empty()) dem.cell_size = std::stod(cell_size);
  if (!crs.empty()) dem.crs = crs;
  return erodem::io::read_dem(dem);
}

/// Largest |a - b| over cells valid in both; counts cells valid in one only in `mismatch`.
double max_difference(const erodem::Terrain& a, const erodem::Terrain& b, std::size_t& mismatch) {
  double worst = 0.0;
  mismatch = 0;
  for (std::size_t i = 0; i < a.bed.size(); ++i) {
    if (a.active(i) != b.active(i)) {
      ++mismatch;
      continue;
    }
    if (a.active(i)) worst = std::max(worst, std::abs(a.bed[i] - b.bed[i]));
  }
  return worst;
}

TEST_F(DemInputs, EveryPromisedFormatReadsTheSameTerrain) {
  if (sh("command -v gdal_translate") != 0) GTEST_SKIP() << "gdal_translate is not installed";
  // Big Tujunga (UTM 11N, Int16) as GeoTIFF, and converted by GDAL to the other formats.
  erodem::Params::Dem window;
  window.path = kTujunga;
  window.window = std::array<int, 4>{300, 200, 120, 90};
  const auto ref = erodem::io::read_dem(window);
  const std::string src = "-srcwin 300 200 120 90 '" + kTujunga + "'";
  struct Format {
    const char* name;
    const char* driver;
    const char* file;
  };
  for (const Format& f :
       {Format{"ESRI ASCII grid", "AAIGrid", "t.asc"}, Format{"ENVI", "ENVI", "t.bin"},
        Format{"netCDF", "netCDF", "t.nc"}, Format{"GeoTIFF (deflate)", "GTiff", "t.tif"}}) {
    ASSERT_EQ(sh(std::string("gdal_translate -q -of ") + f.driver + " " + src + " " + f.file), 0)
        << f.name;
    const auto t = read(file(f.file));
    ASSERT_EQ(t.grid.nx, ref.grid.nx) << f.name;
    ASSERT_EQ(t.grid.ny, ref.grid.ny) << f.name;
    std::size_t mismatch = 0;
    const double diff = max_difference(ref, t, mismatch);
    double transform_diff = 0.0;
    for (int k = 0; k < 6; ++k)
      transform_diff = std::max(
          transform_diff, std::abs(t.grid.georef.transform[k] - ref.grid.georef.transform[k]));
    std::printf(
        "  %-18s %d x %d, dx %.4f m, elevation max diff %.3g m (bound 0), transform max "
        "diff %.3g (bound 1e-6), mask mismatches %zu\n",
        f.name, t.grid.nx, t.grid.ny, t.grid.dx.front(), diff, transform_diff, mismatch);
    EXPECT_EQ(diff, 0.0) << f.name;
    EXPECT_EQ(mismatch, 0u) << f.name;
    EXPECT_LT(transform_diff, 1e-6) << f.name;
    EXPECT_FALSE(t.grid.georef.is_geographic) << f.name;
    EXPECT_NEAR(t.grid.dx.front(), ref.grid.dx.front(), 1e-9) << f.name;
  }

  // SRTM HGT: a 1-degree tile N32W097 (1201 x 1201, 3 arc-seconds, WGS84) made from the
  // Dallas-Fort Worth SRTM3 DEM; the HGT driver knows its georeferencing from the name.
  ASSERT_EQ(sh("gdal_translate -q -of SRTMHGT -outsize 1201 1201 -a_ullr -97.0004166667 "
               "33.0004166667 -95.9995833333 31.9995833333 '" +
               kDfw + "' N32W097.hgt"),
            0);
  const auto hgt = read(file("N32W097.hgt"));
  ASSERT_EQ(hgt.grid.nx, 1201);
  ASSERT_EQ(hgt.grid.ny, 1201);
  EXPECT_TRUE(hgt.grid.georef.is_geographic);
  // 3 arc-seconds of latitude are 92.4 m there; of longitude, 92.6 m * cos(lat).
  const double dy = hgt.grid.dy[600], dx_north = hgt.grid.dx.front(), dx_south = hgt.grid.dx.back();
  const double lat_mid = 32.5 * M_PI / 180.0;
  std::printf(
      "  SRTM HGT          1201 x 1201, dy %.3f m, dx %.3f (north) .. %.3f (south) m, "
      "dx / (dy cos(lat)) at mid row %.5f (bound 1 +- 0.01)\n",
      dy, dx_north, dx_south, hgt.grid.dx[600] / (dy * std::cos(lat_mid)));
  EXPECT_NEAR(dy, 92.4, 0.5);
  EXPECT_NEAR(hgt.grid.dx[600] / (dy * std::cos(lat_mid)), 1.0, 0.01);
  EXPECT_LT(dx_north, dx_south);  // meridians converge northwards
  double lo = 1e30, hi = -1e30;
  std::size_t valid = 0;
  for (std::size_t i = 0; i < hgt.bed.size(); ++i)
    if (hgt.active(i)) {
      lo = std::min(lo, hgt.bed[i]);
      hi = std::max(hi, hgt.bed[i]);
      ++valid;
    }
  std::printf(
      "  SRTM HGT          elevations %.0f .. %.0f m (DEM: 147 .. 298 m), %zu valid cells\n", lo,
      hi, valid);
  EXPECT_GE(lo, 147.0);
  EXPECT_LE(hi, 298.0);
  EXPECT_GT(valid, hgt.bed.size() / 2);
}

const char* kRunConfig = R"([time]
steps = 5
dt = 0.1
[rain]
rate = "10 mm/h"
[output]
path = "out.h5"
)";

/// `erodem run` on `dem_lines` (the [dem] table's body) in `t`'s folder: the exit code, and
/// checks the message is one line naming `must_name`, and nothing named out* was left.
void expect_clean_failure(const DemInputs& t, const std::string& what, const std::string& dem_lines,
                          int code, const std::string& must_name, const std::string& extra = "") {
  t.write("c.toml", "[dem]\n" + dem_lines + "\n" + kRunConfig);
  const auto r = run_cli("run c.toml --backend cpu " + extra, t.dir_);
  std::string out = r.output;
  while (!out.empty() && out.back() == '\n') out.pop_back();
  const auto lines = std::count(out.begin(), out.end(), '\n') + 1;
  std::printf("  [%s] exit %d (expected %d), %ld line(s): %s\n", what.c_str(), r.code, code,
              static_cast<long>(lines), out.c_str());
  EXPECT_EQ(r.code, code) << what;
  EXPECT_EQ(lines, 1) << what << ": " << r.output;
  EXPECT_NE(r.output.find(must_name), std::string::npos) << what << ": " << r.output;
  EXPECT_EQ(t.files_matching("out"), 0u) << what << ": output left behind";
}

TEST_F(DemInputs, BadInputIsAOneLineErrorWithTheDocumentedCodeAndNoOutput) {
  // A truncated GeoTIFF: the header reads, the pixels do not.
  {
    std::ifstream in(kTujunga, std::ios::binary);
    std::vector<char> head(200000);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::ofstream(file("truncated.tif"), std::ios::binary).write(head.data(), in.gcount());
  }
  expect_clean_failure(*this, "truncated GeoTIFF", "path = \"truncated.tif\"", 65, "truncated.tif");
  // Not a raster at all.
  write("notes.tif", "elevation data will go here\n");
  expect_clean_failure(*this, "non-raster file", "path = \"notes.tif\"", 65, "notes.tif");
  // Every cell nodata.
  {
    const auto v = read(kVolcano, "10");
    const std::vector<float> all_nodata(v.grid.cells(), -9999.0f);
    erodem::io::write_geotiff(file("empty.tif"), v.grid, all_nodata, "all nodata", -9999.0);
  }
  expect_clean_failure(*this, "all cells nodata", "path = \"empty.tif\"", 65, "empty.tif");
  // A window outside the raster.
  expect_clean_failure(
      *this, "window outside",
      "path = \"" + kVolcano + "\"\ncell_size = \"10 m\"\nwindow = [80, 0, 20, 20]", 65, "window");
  // A missing DEM.
  expect_clean_failure(*this, "missing DEM", "path = \"nowhere.tif\"", 66, "nowhere.tif");
  // Unwritable output: a folder that does not exist, and a "folder" that is a file.
  expect_clean_failure(*this, "output folder missing",
                       "path = \"" + kVolcano + "\"\ncell_size = \"10 m\"", 73, "no_such_dir",
                       "--output no_such_dir/out.h5");
  write("plainfile", "x");
  expect_clean_failure(*this, "output folder is a file",
                       "path = \"" + kVolcano + "\"\ncell_size = \"10 m\"", 73, "plainfile",
                       "--output plainfile/out.h5");
  // `erodem info` says the same about the bad files.
  for (const char* bad : {"truncated.tif", "notes.tif"}) {
    const auto r = run_cli(std::string("info ") + bad, dir_);
    std::printf("  [info %s] exit %d: %s", bad, r.code, r.output.c_str());
    EXPECT_EQ(r.code, 65) << bad << ": " << r.output;
    EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
  }
}

}  // namespace
