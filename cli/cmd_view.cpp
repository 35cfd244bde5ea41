// `erodem view RUN.h5|DEM`: the VTK viewer (viz/, docs/viewer.md). With --screenshot it
// renders off screen and exits; with --pick it picks the terrain at a CRS point through the
// renderer and prints the cell's values as JSON.
#include <fmt/format.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/results.hpp"

#ifdef ERODEM_HAVE_VIEWER
#include "erodem/viz/colormap.hpp"
#include "erodem/viz/scene.hpp"
#include "erodem/viz/view_data.hpp"
#endif

namespace erodem::cli {

namespace {

struct ViewOptions {
  std::string input, field = "bed", screenshot, size = "1200x800", pick, keys;
  std::string cmap, clim, series;
  double time = NAN;  // NaN: the last snapshot
  long snapshot = 0;
  bool has_snapshot = false, rescale = false, no_water = false;
  double exaggeration = 0.0;
  double water_threshold = 0.05;
  double max_cells = 4e6;
  double interaction_cells = 1e5;
  double cell_size = 0.0, z_scale = 1.0;
  double snow_line = NAN;
  std::string crs;
  bool overwrite = false, top = false, timing = false;
};

#ifdef ERODEM_HAVE_VIEWER
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

/// "LO,HI" with LO < HI.
std::array<double, 2> parse_clim(const std::string& s) {
  double lo = NAN, hi = NAN;
  char extra = 0;
  if (std::sscanf(s.c_str(), "%lf,%lf%c", &lo, &hi, &extra) != 2 || !std::isfinite(lo) ||
      !std::isfinite(hi) || !(lo < hi))
    throw Error(
        ExitCode::usage,
        "--clim: expected LO,HI with LO < HI in the field's units, e.g. -0.5,0.5; got '" + s + "'");
  return {lo, hi};
}

/// The picked cell's time series as CSV: time_s, then every field (NaN: empty).
void write_series_csv(const std::string& path, const std::vector<viz::CellValues>& series) {
  const std::filesystem::path target(path);
  const std::filesystem::path tmp = erodem::io::partial_path(path);  // unique to this process
  {
    std::FILE* f = std::fopen(tmp.string().c_str(), "w");
    if (!f) throw Error(ExitCode::cant_create, path + ": could not create the file");
    std::string head = "time_s";
    if (!series.empty())
      for (const auto& [name, v] : series.front().values) head += "," + name;
    std::fprintf(f, "%s\n", head.c_str());
    for (const auto& c : series) {
      std::string line = fmt::format("{:.17g}", c.time);
      for (const auto& [name, v] : c.values)
        line += std::isfinite(v) ? fmt::format(",{:.9g}", v) : std::string(",");
      std::fprintf(f, "%s\n", line.c_str());
    }
    if (std::fclose(f) != 0) throw Error(ExitCode::io, path + ": could not write the file");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(ExitCode::cant_create, path + ": could not create the file: " + ec.message());
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// What was drawn, on stderr: the colour map and range, the clipped ends, the scale bar and
/// the north arrow (the figures the tests check against the pixels).
void describe_drawing(const viz::Scene& scene) {
  const auto lim = scene.color_limits();
  const auto clip = scene.clipped();
  const auto bar = scene.scale_bar();
  std::fprintf(stderr,
               "erodem view: colour map %s, range %.6g .. %.6g, clipped below: %s, above: %s; "
               "scale bar %g m = %.2f px; north %.1f deg from up\n",
               viz::color_map_name(scene.color_map()).c_str(), lim[0], lim[1],
               clip[0] ? "yes" : "no", clip[1] ? "yes" : "no", bar.metres, bar.pixels,
               bar.north_degrees);
}

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
  if (!o.series.empty()) {
    if (o.pick.empty()) throw Error(ExitCode::usage, "--series: needs --pick X,Y (the cell)");
    check_output_path(o.series, o.overwrite);
  }
  if (o.has_snapshot && !std::isnan(o.time))
    throw Error(ExitCode::usage, "--snapshot: give either --time or --snapshot, not both");
  std::optional<std::array<double, 2>> clim;
  if (!o.clim.empty()) clim = parse_clim(o.clim);
  std::optional<viz::ColorMap> cmap;
  if (!o.cmap.empty()) cmap = viz::color_map_by_name(o.cmap);
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
  if (o.has_snapshot) {
    so.time_index = data.snapshot_index(o.snapshot);
  } else if (std::isnan(o.time)) {
    so.time_index = data.times().size() - 1;
  } else {
    // Adaptive runs store times such as 3599.87 s: take the nearest snapshot, and say which
    // when it is not the time asked for.
    so.time_index = data.nearest_time_index(o.time);
    const double t = data.times()[so.time_index];
    if (std::abs(t - o.time) > 1e-9 * std::max(1.0, std::abs(o.time)))
      std::fprintf(
          stderr,
          "erodem view: --time %g s: showing the nearest snapshot, %d of 0..%zu at t = %.17g s\n",
          o.time, static_cast<int>(so.time_index), data.times().size() - 1, t);
  }
  so.cmap = cmap;
  so.clim = clim;
  so.rescale = o.rescale;
  so.water = !o.no_water;
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
    if (!o.series.empty()) {
      write_series_csv(o.series, data.cell_series(hit->cell.col, hit->cell.row));
      std::fprintf(stderr, "erodem view: wrote %s: cell (col %d, row %d) at %zu snapshots\n",
                   o.series.c_str(), hit->cell.col, hit->cell.row, data.times().size());
    }
  }
  if (!o.screenshot.empty()) {
    const auto t4 = clock::now();
    scene.write_png(o.screenshot);
    std::fprintf(stderr, "erodem view: rendered and written in %.2f s\n", seconds_since(t4));
  }
  if (!o.screenshot.empty() || !o.pick.empty()) describe_drawing(scene);
  if (!o.screenshot.empty()) {
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
  sub->add_option("--time", o->time,
                  "Time to show (s): the nearest stored snapshot (named on stderr when not "
                  "exact); default: the last snapshot");
  sub->add_option("--snapshot", o->snapshot,
                  "Snapshot to show by number: 0-based, negative from the end (-1 = last)")
      ->each([o](const std::string&) { o->has_snapshot = true; });
  sub->add_option("--cmap", o->cmap,
                  "Colour map of --field: terrain, water, sediment, speed, diverging (centred "
                  "on 0), classes; default: the field's own");
  sub->add_option("--clim", o->clim,
                  "Colour range LO,HI of --field (its units); values beyond are drawn in the end "
                  "colours and marked by a triangle on the bar");
  sub->add_flag("--rescale", o->rescale,
                "Recompute the colour range at every snapshot (default: one range held over "
                "all snapshots)");
  sub->add_flag("--no-water", o->no_water, "Do not draw the water surface");
  sub->add_option("--series", o->series,
                  "With --pick: write the picked cell's values at every snapshot to this CSV");
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
