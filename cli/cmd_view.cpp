// `erodem view RUN.h5|DEM`: the VTK viewer (viz/, docs/viewer.md). With --screenshot it
// renders off screen and exits; with --pick it picks the terrain at a CRS point through the
// renderer and prints the cell's values as JSON.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/error.hpp"

#ifdef ERODEM_HAVE_VIEWER
#include "erodem/viz/scene.hpp"
#include "erodem/viz/view_data.hpp"
#endif

namespace erodem::cli {

namespace {

struct ViewOptions {
  std::string input, field = "bed", screenshot, size = "1200x800", pick, keys;
  double time = NAN;  // NaN: the last snapshot
  double exaggeration = 0.0;
  double water_threshold = 0.05;
  double max_cells = 4e6;
  double interaction_cells = 1e5;
  double cell_size = 0.0, z_scale = 1.0;
  double snow_line = NAN;
  std::string crs;
  bool overwrite = false, top = false, timing = false;
};

/// "WxH" in pixels.
std::pair<int, int> parse_size(const std::string& s) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
      w < 16 || h < 16 || w > 16384 || h > 16384)
    throw Error(ExitCode::usage,
                "--size: expected WxH in pixels (16..16384 each), e.g. 1200x800; got '" + s + "'");
  return {w, h};
}

/// "X,Y" in the grid's CRS.
std::pair<double, double> parse_point(const std::string& s) {
  double x = NAN, y = NAN;
  char extra = 0;
  if (std::sscanf(s.c_str(), "%lf,%lf%c", &x, &y, &extra) != 2 || !std::isfinite(x) ||
      !std::isfinite(y))
    throw Error(ExitCode::usage,
                "--pick: expected X,Y in the grid's CRS units, e.g. 315.5,-120; got '" + s + "'");
  return {x, y};
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

#ifdef ERODEM_HAVE_VIEWER
int view(const ViewOptions& o) {
  using clock = std::chrono::steady_clock;
  const auto [width, height] = parse_size(o.size);
  std::pair<double, double> pick_point{};
  if (!o.pick.empty()) pick_point = parse_point(o.pick);
  if (!(o.max_cells >= 1.0))
    throw Error(ExitCode::usage, fmt::format("--max-cells: expected >= 1, got {:g}", o.max_cells));
  if (!(o.water_threshold >= 0.0))
    throw Error(ExitCode::usage,
                fmt::format("--water-threshold: expected >= 0 m, got {:g}", o.water_threshold));
  if (!(o.exaggeration >= 0.0))
    throw Error(ExitCode::usage,
                fmt::format("--exaggeration: expected > 0 (0 = auto), got {:g}", o.exaggeration));
  // --keys replays keys in the (interactive) window; with --screenshot it then saves it.
  const bool offscreen = (!o.screenshot.empty() || !o.pick.empty()) && o.keys.empty();
  if (!o.keys.empty() && !o.pick.empty())
    throw Error(ExitCode::usage, "--keys: cannot be combined with --pick");
  if (!o.screenshot.empty()) check_output_path(o.screenshot, o.overwrite);
  if (!offscreen && !std::getenv("DISPLAY"))
    throw Error(ExitCode::usage,
                "no display (DISPLAY is not set): give --screenshot OUT.png (under xvfb-run -a "
                "when headless) or run on a desktop");

  const auto t0 = clock::now();
  viz::DemOptions dem;
  dem.cell_size = o.cell_size;
  dem.z_scale = o.z_scale;
  dem.crs = o.crs;
  viz::ViewData data(o.input, dem);
  data.class_rule.snow_line = o.snow_line;
  viz::SceneOptions so;
  data.field(o.field);  // unknown -> Error naming it
  so.field = o.field;
  so.time_index = std::isnan(o.time) ? data.times().size() - 1 : data.time_index(o.time);
  so.exaggeration = o.exaggeration;
  so.water_threshold = o.water_threshold;
  so.max_cells = static_cast<std::size_t>(o.max_cells);
  so.interaction_cells = static_cast<std::size_t>(std::max(1.0, o.interaction_cells));
  so.width = width;
  so.height = height;
  so.offscreen = offscreen;
  so.top_view = o.top;
  const double read_s = seconds_since(t0);
  if (!o.pick.empty()) {
    int col = 0, row = 0;
    if (!data.grid().locate(pick_point.first, pick_point.second, col, row))
      throw Error(ExitCode::usage, fmt::format("--pick {}: the point is outside the grid", o.pick));
  }
  const auto t1 = clock::now();
  viz::Scene scene(data, so);
  const double build_s = seconds_since(t1);
  std::fprintf(stderr, "erodem view: %s; read in %.2f s, scene built in %.2f s (%s)\n",
               data.describe().c_str(), read_s, build_s,
               scene.lod().factor == 1 ? "full resolution"
                                       : fmt::format("drawn 1:{} as {} x {}", scene.lod().factor,
                                                     scene.lod().coarse_nx, scene.lod().coarse_ny)
                                             .c_str());
  if (!offscreen) {
    std::vector<std::string> keys;
    for (std::size_t a = 0; a < o.keys.size();) {
      std::size_t b = o.keys.find(',', a);
      if (b == std::string::npos) b = o.keys.size();
      if (b > a) keys.push_back(o.keys.substr(a, b - a));
      a = b + 1;
    }
    viz::run_interactive(scene, keys, o.screenshot);
    if (!o.screenshot.empty())
      std::printf("wrote %s: %s at t = %g s (%d x %d pixels) after keys %s\n", o.screenshot.c_str(),
                  scene.field().c_str(), data.times()[scene.time_index()], width, height,
                  o.keys.c_str());
    return 0;
  }
  // A pick needs a rendered frame (the world-to-display transform); a screenshot renders
  // its own.
  double render_s = NAN;
  if (!o.pick.empty() || o.timing) {
    const auto t2 = clock::now();
    scene.render();
    render_s = seconds_since(t2);
    std::fprintf(stderr, "erodem view: first render %.2f s\n", render_s);
  }
  if (o.timing) {
    // Redraws as the camera turns, the steady-state cost of a frame in the window.
    const int frames = 5;
    const auto t5 = clock::now();
    for (int k = 0; k < frames; ++k) {
      scene.orbit(10.0);
      scene.render();
    }
    std::fprintf(stderr, "erodem view: %d redraws turning the camera: %.3f s per frame\n", frames,
                 seconds_since(t5) / frames);
    for (int k = 0; k < frames; ++k) scene.orbit(-10.0);
    scene.render();
  }
  if (!o.pick.empty()) {
    const auto [x, y] = pick_point;
    const auto d = scene.display_of(x, y);
    if (!d)
      throw Error(
          ExitCode::usage,
          fmt::format("--pick {}: the point is outside the grid or on a nodata cell", o.pick));
    const auto t3 = clock::now();
    const auto hit = scene.pick((*d)[0], (*d)[1]);
    if (!hit)
      throw Error(ExitCode::usage,
                  fmt::format("--pick {}: no terrain under display point ({:.1f}, {:.1f}) in this "
                              "view (try --top)",
                              o.pick, (*d)[0], (*d)[1]));
    std::fprintf(stderr, "erodem view: picked at display (%.1f, %.1f) in %.3f s\n", (*d)[0],
                 (*d)[1], seconds_since(t3));
    std::printf("%s\n", viz::pick_json(data, hit->cell).c_str());
  }
  if (!o.screenshot.empty()) {
    const auto t4 = clock::now();
    scene.write_png(o.screenshot);
    std::fprintf(stderr, "erodem view: rendered and written in %.2f s\n", seconds_since(t4));
    std::printf("wrote %s: %s at t = %g s (%d x %d pixels)\n", o.screenshot.c_str(),
                o.field.c_str(), data.times()[scene.time_index()], width, height);
  }
  return 0;
}
#else
int view(const ViewOptions&) {
  throw Error(ExitCode::usage,
              "view: this erodem was built without the viewer (VTK not found or "
              "ERODEM_VIEWER=OFF); install libvtk9-dev and rebuild");
}
#endif

}  // namespace

Action add_view(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  auto* sub =
      app.add_subcommand("view", "Show a result file or DEM in a VTK window (or render it)");
  sub->add_option("input", o->input, "Result file (.h5) or DEM")->required();
  sub->add_option("--field", o->field,
                  "Field to colour the terrain by: a stored field (bed, water_depth, sediment, "
                  "erosion, ...), speed, or terrain_class (default: bed)");
  sub->add_option("--time", o->time, "Stored time to show (s); default: the last snapshot");
  sub->add_option("--screenshot", o->screenshot, "Render off screen to this PNG and exit");
  sub->add_option("--size", o->size, "Window or image size WxH in pixels (default: 1200x800)");
  sub->add_flag("--overwrite", o->overwrite, "Replace an existing screenshot");
  sub->add_option("--pick", o->pick,
                  "Pick the terrain at CRS point X,Y through the renderer (off screen) and "
                  "print the cell's values as JSON");
  sub->add_option("--exaggeration", o->exaggeration,
                  "Vertical exaggeration (1); default: auto, relief ~15 % of the extent, 1..5");
  sub->add_option("--water-threshold", o->water_threshold,
                  "Draw the water surface where the depth exceeds this (m; default 0.05)");
  sub->add_option("--max-cells", o->max_cells,
                  "Draw a block-decimated copy above this many cells (default 4000000); "
                  "picking reads full-resolution values");
  sub->add_option("--interaction-cells", o->interaction_cells,
                  "Window: while the camera moves, draw a copy of at most this many cells "
                  "(default 100000)");
  sub->add_option("--keys", o->keys,
                  "Replay keys in the window first, comma-separated (n,space,Right,plus,...); "
                  "with --screenshot, then save the window and exit");
  sub->add_flag("--timing", o->timing,
                "Off screen: also time 5 redraws of a turning camera (frame time)");
  sub->add_flag("--top", o->top, "Look straight down (north up) instead of obliquely");
  sub->add_option("--snow-line", o->snow_line,
                  "terrain_class: snow above this elevation (m); default: 75 % up the bed range");
  sub->add_option("--cell-size", o->cell_size,
                  "DEMs without georeferencing: cell size (m), as dem.cell_size");
  sub->add_option("--z-scale", o->z_scale, "DEMs: multiplier of the stored values, as dem.z_scale");
  sub->add_option("--crs", o->crs, "DEMs without georeferencing: CRS, as dem.crs");
  return [o] { return view(*o); };
}

}  // namespace erodem::cli
