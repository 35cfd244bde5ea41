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

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

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
