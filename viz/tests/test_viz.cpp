// erodem viewer tests: the pieces (level of detail, world frame, colour ranges, terrain
// classes) and `erodem view` end to end: off-screen renders under xvfb-run, picking through
// the renderer against the values in the file, and the errors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "erodem/error.hpp"
#include "erodem/io/results.hpp"
#include "erodem/viz/colormap.hpp"
#include "erodem/viz/frame.hpp"
#include "erodem/viz/lod.hpp"
#include "erodem/viz/terrain_class.hpp"
#include "erodem/viz/view_data.hpp"

namespace fs = std::filesystem;
using namespace erodem;
using namespace erodem::viz;

// ---- the pieces, without a window ------------------------------------------------------

TEST(VizLod, FactorIsTheSmallestWithinTheBudget) {
  struct Case {
    int nx, ny;
    std::size_t budget;
  };
  for (const Case c : {Case{1025, 1025, 4'000'000}, Case{6000, 6000, 4'000'000}, Case{10, 10, 10},
                       Case{7001, 5003, 1'000'000}, Case{3, 2, 1}}) {
    const Lod lod = Lod::for_budget(c.nx, c.ny, c.budget);
    std::printf("%d x %d, budget %zu: factor %d -> %d x %d = %zu cells\n", c.nx, c.ny, c.budget,
                lod.factor, lod.coarse_nx, lod.coarse_ny, lod.coarse_cells());
    EXPECT_LE(lod.coarse_cells(), c.budget);
    if (lod.factor > 1) {
      const Lod finer{lod.factor - 1, c.nx, c.ny, (c.nx + lod.factor - 2) / (lod.factor - 1),
                      (c.ny + lod.factor - 2) / (lod.factor - 1)};
      EXPECT_GT(finer.coarse_cells(), c.budget) << "factor " << lod.factor - 1 << " fits too";
    }
  }
  EXPECT_EQ(Lod::for_budget(1025, 1025, 4'000'000).factor, 1);
  EXPECT_EQ(Lod::for_budget(6000, 6000, 4'000'000).factor, 3);
}

TEST(VizLod, DecimateAveragesValidCellsAndSamplesCategories) {
  // 5 x 3 grid, factor 2 -> 3 x 2 coarse cells, partial blocks at the east and south edges.
  const std::vector<float> v{1,  2,   3,  4,  5,   //
                             6,  NAN, 8,  9,  10,  //
                             11, 12,  13, 14, 15};
  Lod lod{2, 5, 3, 3, 2};
  const auto mean = decimate(v, lod, Reduce::mean);
  ASSERT_EQ(mean.size(), 6u);
  const std::vector<float> want{(1 + 2 + 6) / 3.f, (3 + 4 + 8 + 9) / 4.f, (5 + 10) / 2.f,
                                (11 + 12) / 2.f,   (13 + 14) / 2.f,       15.f};
  for (std::size_t i = 0; i < want.size(); ++i)
    EXPECT_FLOAT_EQ(mean[i], want[i]) << "coarse cell " << i;
  const auto sample = decimate(v, lod, Reduce::sample);
  EXPECT_EQ(sample[0], 1.f);   // centre of the 2 x 2 block: its first cell
  EXPECT_EQ(sample[2], 5.f);   // 1-wide east block
  EXPECT_EQ(sample[5], 15.f);  // 1 x 1 corner block
  EXPECT_DOUBLE_EQ(lod.fine_col(1), 2.5);
  EXPECT_DOUBLE_EQ(lod.fine_col(2), 4.0);
  EXPECT_DOUBLE_EQ(lod.fine_row(1), 2.0);
}

TEST(VizFrame, RoundTripsProjectedAndGeographicGrids) {
  Grid g = Grid::uniform(100, 80, 30.0);
  g.georef.transform = {500000.0, 30.0, 0.0, 5200000.0, 0.0, -30.0};
  const WorldFrame f = WorldFrame::for_grid(g);
  const auto c = g.cell_center(99, 79);
  const auto w = f.to_world(c[0], c[1]);
  const auto back = f.to_crs(w[0], w[1]);
  std::printf("projected: cell (99, 79) at world (%.3f, %.3f) m, back error %.3g\n", w[0], w[1],
              std::hypot(back[0] - c[0], back[1] - c[1]));
  EXPECT_NEAR(w[0], 49.5 * 30.0, 1e-9);
  EXPECT_NEAR(w[1], -39.5 * 30.0, 1e-9);
  EXPECT_NEAR(back[0], c[0], 1e-6);
  EXPECT_NEAR(back[1], c[1], 1e-6);

  // Geographic: 1/1200 degree cells near 45 N; the grid's own cell sizes give the scales.
  Grid geo = Grid::uniform(100, 100, 1.0);
  geo.georef.is_geographic = true;
  geo.georef.transform = {-120.0, 1.0 / 1200, 0.0, 45.0, 0.0, -1.0 / 1200};
  for (int r = 0; r < geo.ny; ++r) {
    geo.dx[r] = 78846.8 / 1200;  // m per degree of longitude at 45 N, per cell
    geo.dy[r] = 111131.7 / 1200;
  }
  const WorldFrame fg = WorldFrame::for_grid(geo);
  std::printf("geographic: %.1f m per degree east, %.1f m per degree north\n", fg.sx, fg.sy);
  EXPECT_NEAR(fg.sx, 78846.8, 1e-6);
  EXPECT_NEAR(fg.sy, 111131.7, 1e-6);
  const auto p = geo.cell_center(10, 90);
  const auto q = fg.to_crs(fg.to_world(p[0], p[1])[0], fg.to_world(p[0], p[1])[1]);
  EXPECT_NEAR(q[0], p[0], 1e-10);
  EXPECT_NEAR(q[1], p[1], 1e-10);
}

TEST(VizColor, RangesAndMaps) {
  const std::vector<float> e{-0.2f, 0.05f, NAN, 0.5f};
  const auto d = color_range(ColorMap::diverging, e);
  std::printf("diverging range of {-0.2, 0.05, 0.5}: [%g, %g]\n", d[0], d[1]);
  EXPECT_FLOAT_EQ(d[0], -0.5f);
  EXPECT_FLOAT_EQ(d[1], 0.5f);
  const auto s = color_range(ColorMap::terrain, e);
  EXPECT_FLOAT_EQ(s[0], -0.2f);
  EXPECT_FLOAT_EQ(s[1], 0.5f);
  const auto flat = color_range(ColorMap::water, {0.f, 0.f});
  EXPECT_LT(flat[0], flat[1]);
  const auto none = color_range(ColorMap::speed, {NAN});
  EXPECT_LT(none[0], none[1]);
  EXPECT_EQ(color_range(ColorMap::classes, e), (std::array<double, 2>{0.0, 4.0}));
  // The diverging map is white at zero (the middle) and distinct at the ends.
  const auto mid = color_at(ColorMap::diverging, 0.5);
  EXPECT_GT(mid[0] + mid[1] + mid[2], 2.8);
  EXPECT_NE(color_at(ColorMap::diverging, 0.0), color_at(ColorMap::diverging, 1.0));
  EXPECT_EQ(color_at(ColorMap::classes, 2.0 / 4.0), color_stops(ColorMap::classes)[2].rgb);
}

TEST(VizColor, NamesHeldRangesAndTheDivergingQuantile) {
  // --cmap names round-trip; an unknown one is a usage error listing them.
  for (const auto& name : color_map_names())
    EXPECT_EQ(color_map_name(color_map_by_name(name)), name);
  try {
    color_map_by_name("jet");
    ADD_FAILURE() << "no error for 'jet'";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::usage);
    EXPECT_NE(std::string(e.what()).find("diverging"), std::string::npos) << e.what();
  }
  // No range of its own: all zero, constant, no data.
  EXPECT_FALSE(data_color_range(ColorMap::diverging, {0.f, 0.f}));
  EXPECT_FALSE(data_color_range(ColorMap::water, {0.2f, 0.2f}));
  EXPECT_FALSE(data_color_range(ColorMap::speed, {NAN}));
  // The diverging range is the kDivergingQuantile quantile of |v| over non-zero values:
  // 1..100 (and zeros, ignored) -> 90, whatever the sign.
  std::vector<float> v(150, 0.f);
  for (int k = 1; k <= 100; ++k) v[static_cast<std::size_t>(k)] = (k % 2 ? 1.f : -1.f) * k;
  const auto d = color_range(ColorMap::diverging, v);
  std::printf("diverging range of +-1..100 with 50 zeros: [%g, %g] (quantile %g)\n", d[0], d[1],
              kDivergingQuantile);
  EXPECT_EQ(d[1], -d[0]);
  EXPECT_NEAR(d[1], 1.0 + std::ceil(kDivergingQuantile * 99.0), 1e-12);
  // No blue in the diverging map: the water's blue stays distinct from deposition.
  for (double t = 0.0; t <= 1.0; t += 0.05) {
    const auto c = color_at(ColorMap::diverging, t);
    EXPECT_FALSE(c[2] > c[0] + 0.1 && c[2] > c[1] + 0.1 && c[0] < 0.2) << "t = " << t;
  }
}

TEST(VizTerrainClass, SnowWaterRockMudGrass) {
  // 8 x 8 cells of 10 m: a flat plain at 0 m with a wet strip (row 6) and a river (row 7,
  // 0.5 m), a 45-degree ramp in columns 3-5 and a 100 m plateau in columns 6-7.
  Grid g = Grid::uniform(8, 8, 10.0);
  std::vector<float> bed(64, 0.f), wet(64, 0.f);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * 8 + c;
      bed[i] = c >= 6 ? 100.f : c >= 3 ? 10.f * (c - 2) : 0.f;
      if (r == 6) wet[i] = 0.05f;
      if (r == 7) wet[i] = 0.5f;
    }
  const auto k = classify_terrain(g, bed, wet);
  const auto at = [&](int c, int r) {
    return static_cast<int>(k[static_cast<std::size_t>(r) * 8 + c]);
  };
  std::printf("slope at (4, 2): %.3f m/m\n", cell_slope(g, bed, 4, 2));
  EXPECT_EQ(at(7, 2), static_cast<int>(TerrainClass::snow));
  EXPECT_EQ(at(4, 2), static_cast<int>(TerrainClass::rock));
  EXPECT_EQ(at(0, 6), static_cast<int>(TerrainClass::mud));
  EXPECT_EQ(at(0, 2), static_cast<int>(TerrainClass::grass));
  EXPECT_EQ(at(0, 7), static_cast<int>(TerrainClass::water));
  EXPECT_NEAR(cell_slope(g, bed, 4, 2), 1.0, 1e-12);
  // An absolute snow line: only the plateau's 100 m is above 50 m, the ramp's top (40 m) not.
  ClassRule absolute;
  absolute.snow_line = 50.0;
  const auto k50 = classify_terrain(g, bed, wet, absolute);
  EXPECT_EQ(static_cast<int>(k50[2 * 8 + 6]), static_cast<int>(TerrainClass::snow));
  EXPECT_EQ(static_cast<int>(k50[2 * 8 + 5]), static_cast<int>(TerrainClass::rock));
  // A dry DEM (no wetness) has no mud.
  const auto dry = classify_terrain(g, bed, {});
  EXPECT_EQ(static_cast<int>(dry[6 * 8]), static_cast<int>(TerrainClass::grass));
}

// ---- erodem view end to end ------------------------------------------------------------

namespace {

struct CliResult {
  int code = -1;
  std::string output;  // stdout and stderr together
};

/// `erodem ARGS` in `cwd`; with `display`, under xvfb-run (a virtual X display for VTK's
/// OpenGL; without xvfb-run, the DISPLAY of the environment is used).
CliResult run_view_cli(const std::string& args, const fs::path& cwd, bool display = true) {
  const std::string xvfb = ERODEM_XVFB_RUN;
  const bool have_xvfb = !xvfb.empty() && xvfb.find("NOTFOUND") == std::string::npos;
  const std::string prefix =
      display && have_xvfb ? "'" + xvfb + "' -a -s '-screen 0 1600x1200x24' " : std::string();
  const std::string cmd =
      "cd '" + cwd.string() + "' && " + prefix + "'" ERODEM_CLI_PATH "' " + args + " 2>&1";
  CliResult r;
  // xvfb-run -a can lose the race for a display number to another X server starting at
  // the same moment; such a start is retried (the command itself never ran then).
  for (int attempt = 0; attempt < 3; ++attempt) {
    r = CliResult{};
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
    const int status = pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (r.output.find("Xvfb failed to start") == std::string::npos) break;
  }
  return r;
}

/// RGB pixels of a PNG, with its size.
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

Image read_png(const fs::path& path) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.string().c_str());
  reader->Update();
  Image im;
  int dims[3];
  reader->GetOutput()->GetDimensions(dims);
  im.width = dims[0];
  im.height = dims[1];
  auto* a = reader->GetOutput()->GetPointData()->GetScalars();
  if (!a) return im;
  const int nc = a->GetNumberOfComponents();
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
    for (int c = 0; c < 3; ++c)
      im.rgb.push_back(static_cast<unsigned char>(a->GetComponent(i, std::min(c, nc - 1))));
  return im;
}

/// Pixels whose colour differs by more than 8 (of 255) in any channel.
std::size_t changed_pixels(const Image& a, const Image& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i + 2 < a.rgb.size() && i + 2 < b.rgb.size(); i += 3)
    if (std::abs(a.rgb[i] - b.rgb[i]) > 8 || std::abs(a.rgb[i + 1] - b.rgb[i + 1]) > 8 ||
        std::abs(a.rgb[i + 2] - b.rgb[i + 2]) > 8)
      ++n;
  return n;
}

/// The number after `"key": ` in a one-line JSON object (NaN when absent or null).
double json_value(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": (-?[0-9.eE+-]+)");
  std::smatch m;
  return std::regex_search(json, m, re) ? std::stod(m[1]) : NAN;
}

std::string json_line(const std::string& output) {
  std::size_t start = 0;
  while (start < output.size()) {
    const std::size_t end = output.find('\n', start);
    const std::string line = output.substr(start, end - start);
    if (!line.empty() && line[0] == '{') return line;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return "";
}

const char* kRunConfig = R"([dem]
path = "hill.tif"
[initial]
water_depth = 0.0
[time]
steps = 120
dt = 1.0
[rain]
rate = "200 mm/h"
[erosion]
enabled = true
[boundary]
east = "open"
[output]
path = "run.h5"
every = 40
fields = ["bed", "water_depth", "sediment", "velocity_x", "velocity_y", "erosion"]
)";

// Deep water: the hill under 0.5 m, draining to its foot (the tests of the water overlay).
const char* kWetConfig = R"([dem]
path = "hill.tif"
[initial]
water_depth = 0.5
[time]
steps = 60
dt = 1.0
[boundary]
east = "open"
[output]
path = "wet.h5"
every = 20
fields = ["bed", "water_depth", "velocity_x", "velocity_y"]
)";

/// The display position `erodem view --pick` reports on stderr ("picked at display (x, y)").
std::array<double, 2> picked_display(const std::string& output) {
  const std::regex re("picked at display \\(([-0-9.]+), ([-0-9.]+)\\)");
  std::smatch m;
  if (!std::regex_search(output, m, re)) return {NAN, NAN};
  return {std::stod(m[1]), std::stod(m[2])};
}

/// RGB of pixel (x, y) in display coordinates (origin bottom left, as VTK reads a PNG).
std::array<int, 3> pixel(const Image& im, double x, double y) {
  const int i = static_cast<int>(std::lround(x)), j = static_cast<int>(std::lround(y));
  const std::size_t k = (static_cast<std::size_t>(j) * im.width + i) * 3;
  if (i < 0 || j < 0 || i >= im.width || j >= im.height) return {-1, -1, -1};
  return {im.rgb[k], im.rgb[k + 1], im.rgb[k + 2]};
}

/// Pixels of the image with x >= x0 within `tol` of `rgb` (0..255) in every channel.
std::size_t count_colour(const Image& im, int x0, std::array<int, 3> rgb, int tol) {
  std::size_t n = 0;
  for (int j = 0; j < im.height; ++j)
    for (int i = x0; i < im.width; ++i) {
      const std::size_t k = (static_cast<std::size_t>(j) * im.width + i) * 3;
      if (std::abs(im.rgb[k] - rgb[0]) <= tol && std::abs(im.rgb[k + 1] - rgb[1]) <= tol &&
          std::abs(im.rgb[k + 2] - rgb[2]) <= tol)
        ++n;
    }
  return n;
}

std::array<int, 3> rgb255(const std::array<double, 3>& c) {
  return {static_cast<int>(c[0] * 255.0), static_cast<int>(c[1] * 255.0),
          static_cast<int>(c[2] * 255.0)};
}

}  // namespace

class View : public ::testing::Test {
 protected:
  static fs::path dir_;
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("erodem_view_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    const auto g = run_view_cli("generate --kind hill --size 64 --relief 40 hill.tif", dir_, false);
    ASSERT_EQ(g.code, 0) << g.output;
    std::ofstream(dir_ / "c.toml") << kRunConfig;
    const auto r = run_view_cli("run c.toml --backend cpu", dir_, false);
    ASSERT_EQ(r.code, 0) << r.output;
    std::ofstream(dir_ / "wet.toml") << kWetConfig;
    const auto w = run_view_cli("run wet.toml --backend cpu", dir_, false);
    ASSERT_EQ(w.code, 0) << w.output;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void SetUp() override {
    ASSERT_TRUE(fs::exists(dir_ / "run.h5")) << "the test run was not written";
  }
};
fs::path View::dir_;

TEST_F(View, RunHasSeveralSnapshots) {
  io::ResultReader reader((dir_ / "run.h5").string());
  std::printf("snapshots:");
  for (double t : reader.times()) std::printf(" %g", t);
  std::printf(" s\n");
  EXPECT_GE(reader.times().size(), 3u);
}

TEST_F(View, ScreenshotHasTheRequestedSize) {
  const auto r = run_view_cli("view run.h5 --screenshot shot.png --size 320x240", dir_);
  std::printf("%s", r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  const Image im = read_png(dir_ / "shot.png");
  std::printf("image: %d x %d (asked 320 x 240)\n", im.width, im.height);
  EXPECT_EQ(im.width, 320);
  EXPECT_EQ(im.height, 240);
  // Not a blank image: the terrain covers a good part of it with varied colours.
  std::size_t distinct = 0;
  std::vector<bool> seen(1 << 15, false);
  for (std::size_t i = 0; i + 2 < im.rgb.size(); i += 3) {
    const int key = (im.rgb[i] >> 3) << 10 | (im.rgb[i + 1] >> 3) << 5 | (im.rgb[i + 2] >> 3);
    if (!seen[key]) ++distinct, seen[key] = true;
  }
  std::printf("distinct colours (5 bits per channel): %zu (need > 50)\n", distinct);
  EXPECT_GT(distinct, 50u);
  // An existing file is not overwritten without --overwrite.
  const auto again = run_view_cli("view run.h5 --screenshot shot.png --size 320x240", dir_);
  EXPECT_EQ(again.code, 73) << again.output;
  EXPECT_EQ(run_view_cli("view run.h5 --screenshot shot.png --size 320x240 --overwrite", dir_).code,
            0);
}

TEST_F(View, FieldAndTimeChangeThePixels) {
  io::ResultReader reader((dir_ / "run.h5").string());
  const auto& t = reader.times();
  ASSERT_GE(t.size(), 3u);
  const std::string last = std::to_string(t.back()), mid = std::to_string(t[1]);
  const std::string common = " --size 400x300 --overwrite";
  ASSERT_EQ(run_view_cli(
                "view run.h5 --field bed --time " + last + " --screenshot bed.png" + common, dir_)
                .code,
            0);
  ASSERT_EQ(run_view_cli("view run.h5 --field water_depth --time " + last +
                             " --screenshot depth.png" + common,
                         dir_)
                .code,
            0);
  ASSERT_EQ(run_view_cli("view run.h5 --field water_depth --time " + mid +
                             " --screenshot depth_mid.png" + common,
                         dir_)
                .code,
            0);
  ASSERT_EQ(
      run_view_cli("view run.h5 --field terrain_class --screenshot class.png" + common, dir_).code,
      0);
  ASSERT_EQ(run_view_cli("view run.h5 --field speed --screenshot speed.png" + common, dir_).code,
            0);
  const Image bed = read_png(dir_ / "bed.png"), depth = read_png(dir_ / "depth.png"),
              depth_mid = read_png(dir_ / "depth_mid.png"), cls = read_png(dir_ / "class.png"),
              speed = read_png(dir_ / "speed.png");
  const std::size_t total = 400 * 300;
  const std::size_t by_field = changed_pixels(bed, depth),
                    by_time = changed_pixels(depth, depth_mid), by_class = changed_pixels(bed, cls),
                    by_speed = changed_pixels(depth, speed);
  std::printf(
      "changed pixels of %zu: bed vs water_depth %zu, water_depth t = %s vs %s s %zu, "
      "bed vs terrain_class %zu, water_depth vs speed %zu\n",
      total, by_field, last.c_str(), mid.c_str(), by_time, by_class, by_speed);
  EXPECT_GT(by_field, total / 20) << "a different field should recolour the terrain";
  EXPECT_GT(by_time, 100u) << "a different time should change the water";
  EXPECT_GT(by_class, total / 50);
  EXPECT_GT(by_speed, total / 50);
}

TEST_F(View, PickReturnsTheStoredValues) {
  io::ResultReader reader((dir_ / "run.h5").string());
  const Grid& g = reader.grid();
  const std::size_t last = reader.times().size() - 1;
  const auto depth = reader.read_index("water_depth", last);
  const auto bed = reader.read_index("bed", last);
  const auto vx = reader.read_index("velocity_x", last);
  const auto vy = reader.read_index("velocity_y", last);
  // A wet cell off the centre, seen from above and obliquely (south half, facing the camera).
  struct Case {
    int col, row;
    const char* view;
  };
  int wet_col = 40, wet_row = 45;
  for (int r = 36; r < 60; ++r)
    for (int c = 10; c < 54; ++c)
      if (depth[static_cast<std::size_t>(r) * g.nx + c] >
          depth[static_cast<std::size_t>(wet_row) * g.nx + wet_col])
        wet_col = c, wet_row = r;
  for (const Case k :
       {Case{wet_col, wet_row, "--top"}, Case{17, 23, "--top"}, Case{wet_col, wet_row, ""}}) {
    const auto p = g.cell_center(k.col, k.row);
    const std::string args = "view run.h5 --field water_depth --pick " + std::to_string(p[0]) +
                             "," + std::to_string(p[1]) + " " + k.view;
    const auto r = run_view_cli(args, dir_);
    ASSERT_EQ(r.code, 0) << r.output;
    const std::string json = json_line(r.output);
    ASSERT_FALSE(json.empty()) << r.output;
    std::printf("pick (col %d, row %d) %s -> %s\n", k.col, k.row, k.view, json.c_str());
    EXPECT_EQ(json_value(json, "col"), k.col);
    EXPECT_EQ(json_value(json, "row"), k.row);
    const std::size_t i = static_cast<std::size_t>(k.row) * g.nx + k.col;
    std::printf(
        "  water_depth: picked %.9g, stored %.9g; bed: picked %.9g, stored %.9g; "
        "speed: picked %.9g, from the file %.9g\n",
        json_value(json, "water_depth"), depth[i], json_value(json, "bed"), bed[i],
        json_value(json, "speed"), std::hypot(vx[i], vy[i]));
    EXPECT_EQ(static_cast<float>(json_value(json, "water_depth")), depth[i]);
    EXPECT_EQ(static_cast<float>(json_value(json, "bed")), bed[i]);
    EXPECT_FLOAT_EQ(static_cast<float>(json_value(json, "speed")), std::hypot(vx[i], vy[i]));
    EXPECT_NEAR(json_value(json, "x"), p[0], 1e-6);
    EXPECT_NEAR(json_value(json, "y"), p[1], 1e-6);
  }
}

TEST_F(View, PickThroughDecimationReadsFullResolution) {
  // --max-cells 300 draws the 64 x 64 grid 1:4 as 16 x 16; the pick still lands in the
  // full-resolution cell under the point and reads its own stored value.
  io::ResultReader reader((dir_ / "run.h5").string());
  const Grid& g = reader.grid();
  const auto bed = reader.read_index("bed", reader.times().size() - 1);
  const int col = 30, row = 33;
  const auto p = g.cell_center(col, row);
  const auto r = run_view_cli("view run.h5 --top --max-cells 300 --pick " + std::to_string(p[0]) +
                                  "," + std::to_string(p[1]),
                              dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string json = json_line(r.output);
  std::printf("%s\ndecimated pick of (col %d, row %d): %s; stored bed %.9g\n", r.output.c_str(),
              col, row, json.c_str(), bed[static_cast<std::size_t>(row) * g.nx + col]);
  EXPECT_NE(r.output.find("drawn 1:4"), std::string::npos) << r.output;
  const int pc = static_cast<int>(json_value(json, "col")),
            pr = static_cast<int>(json_value(json, "row"));
  // The decimated surface differs a little from the full one, so the ray may land one cell
  // away in a top view; the value must be that cell's own, stored value.
  EXPECT_LE(std::abs(pc - col), 1);
  EXPECT_LE(std::abs(pr - row), 1);
  EXPECT_EQ(static_cast<float>(json_value(json, "bed")),
            bed[static_cast<std::size_t>(pr) * g.nx + pc]);
}

TEST_F(View, WindowKeysSwitchFieldTimeAndView) {
  // The interactive window (under xvfb-run), driven by replayed keys, then saved: the same
  // key handlers a user reaches. "r" only resets the camera: the reference image.
  const std::string common = " --size 400x300 --overwrite";
  const auto ref = run_view_cli("view run.h5 --keys r --screenshot k_ref.png" + common, dir_);
  ASSERT_EQ(ref.code, 0) << ref.output;
  const auto field = run_view_cli("view run.h5 --keys n,n --screenshot k_field.png" + common, dir_);
  ASSERT_EQ(field.code, 0) << field.output;
  const auto time =
      run_view_cli("view run.h5 --keys Left,Left --screenshot k_time.png" + common, dir_);
  ASSERT_EQ(time.code, 0) << time.output;
  const auto view =
      run_view_cli("view run.h5 --keys t,plus,w --screenshot k_view.png" + common, dir_);
  ASSERT_EQ(view.code, 0) << view.output;
  std::printf("%s%s%s%s", ref.output.c_str(), field.output.c_str(), time.output.c_str(),
              view.output.c_str());
  // n, n: bed -> water_depth -> sediment; Left, Left: two snapshots back from the last.
  io::ResultReader reader((dir_ / "run.h5").string());
  const auto& t = reader.times();
  char want_time[64];
  std::snprintf(want_time, sizeof want_time, "at t = %g s", t[t.size() - 3]);
  EXPECT_NE(field.output.find("wrote k_field.png: sediment"), std::string::npos) << field.output;
  EXPECT_NE(time.output.find(want_time), std::string::npos)
      << time.output << " (want " << want_time << ")";
  const Image a = read_png(dir_ / "k_ref.png"), f = read_png(dir_ / "k_field.png"),
              b = read_png(dir_ / "k_time.png"), v = read_png(dir_ / "k_view.png");
  EXPECT_EQ(a.width, 400);
  EXPECT_EQ(a.height, 300);
  const std::size_t by_field = changed_pixels(a, f), by_time = changed_pixels(a, b),
                    by_view = changed_pixels(a, v);
  std::printf("changed pixels of 120000 after keys: field %zu, time %zu, top view %zu\n", by_field,
              by_time, by_view);
  EXPECT_GT(by_field, 2000u);
  EXPECT_GT(by_time, 200u);  // the status line and slider at least, the bed a little
  EXPECT_GT(by_view, 20000u);
}

TEST_F(View, DemScreenshotAndTerrainClasses) {
  const auto r = run_view_cli(
      "view hill.tif --field terrain_class --screenshot dem.png --size 200x150 --overwrite", dir_);
  std::printf("%s", r.output.c_str());
  ASSERT_EQ(r.code, 0) << r.output;
  const Image im = read_png(dir_ / "dem.png");
  EXPECT_EQ(im.width, 200);
  EXPECT_EQ(im.height, 150);
}

TEST_F(View, ErrorsNameWhatIsMissing) {
  // A raster without georeferencing (a binary PGM: no geotransform, no CRS) needs
  // --cell-size; a text file is no raster at all.
  std::ofstream(dir_ / "plain.pgm", std::ios::binary) << "P5\n2 2\n255\n\x01\x02\x03\x04";
  std::ofstream(dir_ / "notes.txt") << "not a raster\n";
  struct Case {
    std::string args;
    int code;
    std::string names;
  };
  for (const Case& c :
       {Case{"view run.h5 --field nosuch --screenshot x.png", 65, "nosuch"},
        Case{"view run.h5 --time 12345 --screenshot x.png", 65, "12345"},
        Case{"view run.h5 --snapshot 4 --screenshot x.png", 2, "--snapshot"},
        Case{"view run.h5 --snapshot -5 --screenshot x.png", 2, "--snapshot"},
        Case{"view run.h5 --time 40 --snapshot 1 --screenshot x.png", 2, "--snapshot"},
        Case{"view run.h5 --cmap jet --screenshot x.png", 2, "jet"},
        Case{"view run.h5 --clim 1,-1 --screenshot x.png", 2, "--clim"},
        Case{"view run.h5 --series s.csv --screenshot x.png", 2, "--series"},
        Case{"view missing.h5 --screenshot x.png", 66, "missing.h5"},
        Case{"view run.h5 --size 12 --screenshot x.png", 2, "--size"},
        Case{"view run.h5 --pick 1e9,1e9", 2, "--pick"},
        Case{"view hill.tif --field water_depth --screenshot x.png", 65, "water_depth"},
        Case{"view plain.pgm --screenshot x.png", 2, "--cell-size"},
        Case{"view notes.txt --screenshot x.png", 65, "notes.txt"}}) {
    const auto r = run_view_cli(c.args, dir_);
    std::printf("erodem %s -> exit %d: %s", c.args.c_str(), r.code, r.output.c_str());
    EXPECT_EQ(r.code, c.code) << c.args;
    EXPECT_NE(r.output.find(c.names), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "x.png"));
  }
}

TEST_F(View, TimeTakesTheNearestSnapshotAndSnapshotCounts) {
  // Snapshots at 0, 40, 80, 120 s: 50 s is nearest to 40 s (snapshot 1), 119.5 s to 120 s;
  // an exact time says nothing; --snapshot -2 is 80 s.
  struct Case {
    std::string args, want_stdout, want_stderr;
  };
  for (const Case& c :
       {Case{"--time 50", "at t = 40 s", "nearest snapshot, 1 of 0..3 at t = 40 s"},
        Case{"--time 119.5", "at t = 120 s", "nearest snapshot, 3 of 0..3"},
        Case{"--time 80", "at t = 80 s", ""}, Case{"--snapshot -2", "at t = 80 s", ""},
        Case{"--snapshot 0", "at t = 0 s", ""}}) {
    const auto r = run_view_cli(
        "view run.h5 " + c.args + " --screenshot t.png --size 160x120 --overwrite", dir_);
    std::printf("erodem view %s -> %s", c.args.c_str(), r.output.c_str());
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find(c.want_stdout), std::string::npos) << c.args;
    if (c.want_stderr.empty())
      EXPECT_EQ(r.output.find("nearest snapshot"), std::string::npos) << c.args;
    else
      EXPECT_NE(r.output.find(c.want_stderr), std::string::npos) << c.args;
  }
}

TEST_F(View, ColourRangeIsHeldOverTimeAndClippedEndsAreMarked) {
  const std::string common = " --size 400x300 --top --overwrite";
  const auto range = [](const std::string& out) {
    const std::regex re("range ([-0-9.e+]+) \\.\\. ([-0-9.e+]+)");
    std::smatch m;
    return std::regex_search(out, m, re) ? std::array<double, 2>{std::stod(m[1]), std::stod(m[2])}
                                         : std::array<double, 2>{NAN, NAN};
  };
  // Held: the same range at snapshots 1 and 3; --rescale: each snapshot its own.
  const auto h1 = run_view_cli(
      "view run.h5 --field water_depth --snapshot 1 --screenshot h1.png" + common, dir_);
  const auto h3 = run_view_cli(
      "view run.h5 --field water_depth --snapshot 3 --screenshot h3.png" + common, dir_);
  const auto r1 = run_view_cli(
      "view run.h5 --field water_depth --snapshot 1 --rescale --screenshot r1.png" + common, dir_);
  const auto r3 = run_view_cli(
      "view run.h5 --field water_depth --snapshot 3 --rescale --screenshot r3.png" + common, dir_);
  for (const auto* r : {&h1, &h3, &r1, &r3}) ASSERT_EQ(r->code, 0) << r->output;
  std::printf("held: %g .. %g and %g .. %g; rescaled: %g .. %g and %g .. %g m\n",
              range(h1.output)[0], range(h1.output)[1], range(h3.output)[0], range(h3.output)[1],
              range(r1.output)[0], range(r1.output)[1], range(r3.output)[0], range(r3.output)[1]);
  EXPECT_EQ(range(h1.output), range(h3.output));
  EXPECT_NE(range(r1.output), range(r3.output));
  // The held range is the map's range of all snapshots' values pooled: here min .. the 99th
  // percentile of water_depth over the 4 snapshots.
  io::ResultReader reader((dir_ / "run.h5").string());
  std::vector<float> pool;
  for (std::size_t k = 0; k < reader.times().size(); ++k) {
    const auto v = reader.read_index("water_depth", k);
    pool.insert(pool.end(), v.begin(), v.end());
  }
  const auto want = color_range(ColorMap::water, pool);
  std::printf("pooled over the snapshots: %.6g .. %.6g m\n", want[0], want[1]);
  EXPECT_NEAR(range(h1.output)[0], want[0], 1e-5 * std::abs(want[1]));
  EXPECT_NEAR(range(h1.output)[1], want[1], 1e-5 * std::abs(want[1]));
  // --clim inside the erosion's range on both sides (half its minimum and maximum at the last
  // snapshot): triangles in the end colours beside the bar (x >= 84 % of the width, where
  // the top view has no terrain); a --clim wider than the data: none.
  const auto e = reader.read_index("erosion", reader.times().size() - 1);
  float e_lo = 0.f, e_hi = 0.f;
  for (float v : e)
    if (std::isfinite(v)) e_lo = std::min(e_lo, v), e_hi = std::max(e_hi, v);
  ASSERT_LT(e_lo, 0.f);
  ASSERT_GT(e_hi, 0.f);
  char clim[64];
  std::snprintf(clim, sizeof clim, "%.6g,%.6g", 0.5 * e_lo, 0.5 * e_hi);
  std::printf("erosion %g .. %g m: --clim %s\n", e_lo, e_hi, clim);
  const auto narrow = run_view_cli(std::string("view run.h5 --field erosion --clim ") + clim +
                                       " --screenshot narrow.png" + common,
                                   dir_);
  const auto wide = run_view_cli(
      "view run.h5 --field erosion --clim -100,100 --screenshot wide.png" + common, dir_);
  ASSERT_EQ(narrow.code, 0) << narrow.output;
  ASSERT_EQ(wide.code, 0) << wide.output;
  std::printf("%s%s", narrow.output.c_str(), wide.output.c_str());
  EXPECT_NE(narrow.output.find("clipped below: yes, above: yes"), std::string::npos);
  EXPECT_NE(wide.output.find("clipped below: no, above: no"), std::string::npos);
  const Image n = read_png(dir_ / "narrow.png"), w = read_png(dir_ / "wide.png");
  const auto lo = rgb255(color_at(ColorMap::diverging, 0.0)),
             hi = rgb255(color_at(ColorMap::diverging, 1.0));
  const int x0 = static_cast<int>(0.84 * 400);
  const std::size_t n_lo = count_colour(n, x0, lo, 3), n_hi = count_colour(n, x0, hi, 3),
                    w_lo = count_colour(w, x0, lo, 3), w_hi = count_colour(w, x0, hi, 3);
  std::printf(
      "end-colour pixels right of x = %d: clipped %zu below, %zu above; not clipped %zu, %zu\n", x0,
      n_lo, n_hi, w_lo, w_hi);
  EXPECT_GT(n_lo, w_lo + 40) << "no triangle below the bar";
  EXPECT_GT(n_hi, w_hi + 40) << "no triangle above the bar";
}

TEST_F(View, ErosionMapColoursTheBulkAndWaterIsBlue) {
  // Erosion at the last snapshot, from the file: the cells at the 75th and 90th percentiles
  // of |erosion| (non-zero) must be coloured (saturation > 40 of 255) in the erosion map,
  // orange where the bed was lowered, purple where it was raised. (The median is printed.)
  io::ResultReader reader((dir_ / "run.h5").string());
  const Grid& g = reader.grid();
  const auto last = reader.times().size() - 1;
  const auto e = reader.read_index("erosion", last);
  std::vector<std::pair<float, std::size_t>> mag;
  for (std::size_t i = 0; i < e.size(); ++i)
    if (std::isfinite(e[i]) && e[i] != 0.f) mag.emplace_back(std::abs(e[i]), i);
  ASSERT_GT(mag.size(), 100u);
  std::sort(mag.begin(), mag.end());
  const std::string top = " --field erosion --top --no-water --size 400x400 --overwrite";
  const auto shot = run_view_cli("view run.h5 --screenshot ero.png" + top, dir_);
  ASSERT_EQ(shot.code, 0) << shot.output;
  std::printf("%s", shot.output.c_str());
  const Image im = read_png(dir_ / "ero.png");
  for (double q : {0.5, 0.75, 0.9}) {
    const std::size_t i = mag[static_cast<std::size_t>(q * (mag.size() - 1))].second;
    const int col = static_cast<int>(i % g.nx), row = static_cast<int>(i / g.nx);
    const auto p = g.cell_center(col, row);
    const auto r = run_view_cli(
        "view run.h5 --pick " + std::to_string(p[0]) + "," + std::to_string(p[1]) + top, dir_);
    ASSERT_EQ(r.code, 0) << r.output;
    const auto d = picked_display(r.output);
    const auto c = pixel(im, d[0], d[1]);
    const int sat = std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]});
    std::printf(
        "|erosion| quantile %.2f: cell (%d, %d) erosion %.4g m at display (%.0f, %.0f): "
        "rgb (%d, %d, %d), saturation %d\n",
        q, col, row, e[i], d[0], d[1], c[0], c[1], c[2], sat);
    if (q < 0.7) continue;
    EXPECT_GT(sat, 40) << "pale (white) at a typical erosion value";
    if (e[i] > 0)
      EXPECT_GT(c[0], c[2]) << "erosion should be orange";
    else
      EXPECT_GT(c[2], c[1]) << "deposition should be purple";
  }

  // Water: a cell 0.3 m deep or more in wet.h5 is blue with the water drawn, and its terrain
  // colour (not blue) with --no-water.
  io::ResultReader wet((dir_ / "wet.h5").string());
  const auto depth = wet.read_index("water_depth", wet.times().size() - 1);
  std::size_t deep = 0;
  for (std::size_t i = 0; i < depth.size(); ++i)
    if (std::isfinite(depth[i]) && depth[i] > depth[deep]) deep = i;
  // A deep cell away from the edge (the mesh stops at the outer cell centres).
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const int c = static_cast<int>(i % g.nx), r = static_cast<int>(i / g.nx);
    if (c > 4 && r > 4 && c < g.nx - 5 && r < g.ny - 5 && depth[i] > 0.3f) {
      deep = i;
      break;
    }
  }
  ASSERT_GT(depth[deep], 0.3f);
  const int col = static_cast<int>(deep % g.nx), row = static_cast<int>(deep / g.nx);
  const auto p = g.cell_center(col, row);
  const std::string at = std::to_string(p[0]) + "," + std::to_string(p[1]);
  const std::string common = " --field bed --top --size 400x400 --overwrite";
  const auto pk = run_view_cli("view wet.h5 --pick " + at + common, dir_);
  const auto with = run_view_cli("view wet.h5 --screenshot water.png" + common, dir_);
  const auto without = run_view_cli("view wet.h5 --no-water --screenshot dry.png" + common, dir_);
  for (const auto* r : {&pk, &with, &without}) ASSERT_EQ(r->code, 0) << r->output;
  const auto d = picked_display(pk.output);
  const auto a = pixel(read_png(dir_ / "water.png"), d[0], d[1]),
             b = pixel(read_png(dir_ / "dry.png"), d[0], d[1]);
  std::printf(
      "cell (%d, %d), %.3f m deep, at display (%.0f, %.0f): water rgb (%d, %d, %d), "
      "--no-water rgb (%d, %d, %d)\n",
      col, row, depth[deep], d[0], d[1], a[0], a[1], a[2], b[0], b[1], b[2]);
  EXPECT_GT(a[2], a[0] + 80) << "water should be blue";
  EXPECT_GT(a[2], a[1] + 30) << "water should be blue, not cyan or grey";
  EXPECT_LT(b[2], b[1]) << "--no-water should show the terrain colour";
}

TEST_F(View, ScaleBarAndNorthArrowMatchTheRenderer) {
  // Top view: two picks 40 cells apart along a row are (40 dx) m apart on the ground; their
  // display positions must be (40 dx) * pixels / metres of the scale bar apart.
  io::ResultReader reader((dir_ / "run.h5").string());
  const Grid& g = reader.grid();
  const std::string common = " --top --size 600x400";
  const auto a = g.cell_center(12, 32), b = g.cell_center(52, 32);
  const auto ra = run_view_cli(
      "view run.h5 --pick " + std::to_string(a[0]) + "," + std::to_string(a[1]) + common, dir_);
  const auto rb = run_view_cli(
      "view run.h5 --pick " + std::to_string(b[0]) + "," + std::to_string(b[1]) + common, dir_);
  ASSERT_EQ(ra.code, 0) << ra.output;
  ASSERT_EQ(rb.code, 0) << rb.output;
  const std::regex re("scale bar ([0-9.e+]+) m = ([0-9.]+) px; north ([-0-9.]+) deg");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ra.output, m, re)) << ra.output;
  const double metres = std::stod(m[1]), px = std::stod(m[2]), north = std::stod(m[3]);
  const auto da = picked_display(ra.output), db = picked_display(rb.output);
  const double ground = 40.0 * g.dx[32], on_screen = std::hypot(db[0] - da[0], db[1] - da[1]);
  std::printf(
      "scale bar %g m = %.2f px (%.5f px/m); picks %.1f m apart are %.2f px apart "
      "(%.5f px/m); north %.1f deg\n",
      metres, px, px / metres, ground, on_screen, on_screen / ground, north);
  // Exact at the focal point's depth; the picked cells lie lower on the hill, further from the
  // camera, so they are a little smaller on screen (perspective).
  EXPECT_NEAR(px / metres, on_screen / ground, 0.03 * on_screen / ground);
  EXPECT_NEAR(north, 0.0, 0.5);
  // The bar is 10..20 % of the width (1, 2 or 5 times a power of ten).
  EXPECT_GE(px, 0.08 * 600);
  EXPECT_LE(px, 0.2 * 600 + 1);
  // Oblique (from the south): north still points up the screen.
  const auto ob = run_view_cli("view run.h5 --screenshot ob.png --size 600x400 --overwrite", dir_);
  ASSERT_TRUE(std::regex_search(ob.output, m, re)) << ob.output;
  std::printf("oblique: scale bar %s m = %s px, north %s deg\n", m[1].str().c_str(),
              m[2].str().c_str(), m[3].str().c_str());
  EXPECT_NEAR(std::stod(m[3]), 0.0, 0.5);
  // The arrow and the bar are drawn: white pixels at the bar's place (bottom right) and at
  // the arrow's (left of the bar).
  const Image im = read_png(dir_ / "ob.png");
  std::size_t arrow = 0, bar = 0;
  for (int j = 0; j < im.height; ++j)
    for (int i = 0; i < im.width; ++i) {
      const auto c = pixel(im, i, j);
      if (c[0] < 240 || c[1] < 240 || c[2] < 240) continue;
      if (i > 600 - 20 - px - 60 && i < 600 - 20 - px - 10 && j < 70) ++arrow;
      if (i > 600 - 20 - px - 2 && i < 600 - 18 && j >= 20 && j <= 30) ++bar;
    }
  std::printf("white pixels: north arrow %zu, scale bar %zu\n", arrow, bar);
  EXPECT_GT(arrow, 60u);
  EXPECT_GT(bar, 100u);
}

TEST_F(View, PickMarksTheCellAndWritesItsSeries) {
  io::ResultReader reader((dir_ / "wet.h5").string());
  const Grid& g = reader.grid();
  const int col = 20, row = 40;
  const auto p = g.cell_center(col, row);
  const std::string at = std::to_string(p[0]) + "," + std::to_string(p[1]);
  const auto r = run_view_cli("view wet.h5 --top --size 400x400 --overwrite --pick " + at +
                                  " --series series.csv --screenshot marked.png",
                              dir_);
  const auto plain =
      run_view_cli("view wet.h5 --top --size 400x400 --overwrite --screenshot plain.png", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_EQ(plain.code, 0) << plain.output;
  std::printf("%s", r.output.c_str());
  // The marker: magenta pixels within 15 px of the picked point, none without a pick.
  const auto d = picked_display(r.output);
  const auto magenta = [&](const Image& im) {
    std::size_t n = 0;
    for (int j = -15; j <= 15; ++j)
      for (int i = -15; i <= 15; ++i) {
        const auto c = pixel(im, d[0] + i, d[1] + j);
        if (c[0] > 150 && c[2] > 150 && c[1] < 80) ++n;
      }
    return n;
  };
  const std::size_t marked = magenta(read_png(dir_ / "marked.png")),
                    unmarked = magenta(read_png(dir_ / "plain.png"));
  std::printf("magenta pixels around the pick: %zu marked, %zu without a pick\n", marked, unmarked);
  EXPECT_GT(marked, 30u);
  EXPECT_EQ(unmarked, 0u);
  // The chart of the series (left, 42..82 % of the height, 36 % of the width): its light
  // panel and the speed curve's orange, neither there without a pick.
  const auto chart = [](const Image& im) {
    std::array<std::size_t, 2> n{0, 0};
    for (int j = static_cast<int>(0.45 * im.height); j < static_cast<int>(0.8 * im.height); ++j)
      for (int i = 2; i < static_cast<int>(0.35 * im.width); ++i) {
        const auto c = pixel(im, i, j);
        if (std::abs(c[0] - 245) <= 3 && std::abs(c[1] - 245) <= 3 && std::abs(c[2] - 240) <= 3)
          ++n[0];
        if (std::abs(c[0] - 230) <= 25 && std::abs(c[1] - 120) <= 25 && c[2] <= 60) ++n[1];
      }
    return n;
  };
  const auto with_chart = chart(read_png(dir_ / "marked.png")),
             no_chart = chart(read_png(dir_ / "plain.png"));
  std::printf(
      "chart region: %zu panel and %zu speed-curve pixels with a pick, %zu and %zu "
      "without\n",
      with_chart[0], with_chart[1], no_chart[0], no_chart[1]);
  EXPECT_GT(with_chart[0], 10000u);
  EXPECT_GT(with_chart[1], 30u);
  EXPECT_EQ(no_chart[0], 0u);
  EXPECT_EQ(no_chart[1], 0u);
  // The series: one row per snapshot, equal to the file's values at the cell.
  std::ifstream in(dir_ / "series.csv");
  std::string header;
  std::getline(in, header);
  std::printf("series.csv: %s\n", header.c_str());
  std::vector<std::string> names;
  for (std::size_t a = 0; a <= header.size();) {
    std::size_t b = header.find(',', a);
    if (b == std::string::npos) b = header.size();
    names.push_back(header.substr(a, b - a));
    a = b + 1;
  }
  const auto column = [&](const std::string& n) {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  ASSERT_LT(column("water_depth"), names.size());
  ASSERT_LT(column("speed"), names.size());
  ASSERT_LT(column("bed"), names.size());
  const std::size_t i = static_cast<std::size_t>(row) * g.nx + col;
  std::size_t rows = 0;
  for (std::string line; std::getline(in, line); ++rows) {
    std::vector<double> v;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');)
      v.push_back(cell.empty() ? NAN : std::stod(cell));
    ASSERT_LT(rows, reader.times().size());
    ASSERT_EQ(v.size(), names.size()) << line;
    const auto depth = reader.read_index("water_depth", rows), bed = reader.read_index("bed", rows),
               vx = reader.read_index("velocity_x", rows),
               vy = reader.read_index("velocity_y", rows);
    std::printf("  %s\n", line.c_str());
    EXPECT_EQ(v[0], reader.times()[rows]);
    EXPECT_EQ(static_cast<float>(v[column("water_depth")]), depth[i]);
    EXPECT_EQ(static_cast<float>(v[column("bed")]), bed[i]);
    EXPECT_FLOAT_EQ(static_cast<float>(v[column("speed")]), std::hypot(vx[i], vy[i]));
  }
  EXPECT_EQ(rows, reader.times().size());
}
