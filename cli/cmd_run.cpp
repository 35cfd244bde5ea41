// `erodem run CONFIG.toml`: runs an experiment and prints the mass ledger.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/schema.hpp"

namespace erodem::cli {

namespace {

std::atomic<bool> g_interrupted{false};
void on_sigint(int) {
  g_interrupted = true;
}

struct RunOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string backend = "auto";
  std::string output;
  bool dump_config = false;
  bool overwrite = false;
};

/// Where field `name` of a run whose output is `path` goes (GeoTIFF until HDF5 lands):
/// run.h5 -> run_bed.tif, run_water_depth.tif, ...
std::string field_path(const std::string& path, const std::string& name) {
  std::filesystem::path p(path);
  p.replace_extension();
  return p.string() + "_" + name + ".tif";
}

/// Progress on a terminal (a bar redrawn in place) or in a log (a line every 10 %).
class Progress {
 public:
  explicit Progress(bool terminal) : terminal_(terminal), start_(Clock::now()), last_(start_) {}
  void update(const Simulation& sim) {
    const auto now = Clock::now();
    const double frac = sim.progress();
    if (terminal_) {
      if (now - last_ < std::chrono::milliseconds(200) && frac < 1.0) return;
      last_ = now;
      const int width = 30, filled = static_cast<int>(frac * width);
      const double elapsed = seconds(now - start_);
      const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0.0;
      std::fprintf(stderr, "\r[%s%s] %5.1f%%  step %ld  t %.5g s  dt %.3g s  eta %.0f s ",
                   std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                   100 * frac, sim.steps_done(), sim.time(), sim.diagnostics().dt, eta);
      std::fflush(stderr);
    } else {
      const int decile = static_cast<int>(frac * 10);
      if (decile <= decile_) return;
      decile_ = decile;
      spdlog::info(
          "{:3d}% step {} t {:.6g} s, water {:.6e} m^3, max depth {:.4g} m, max speed "
          "{:.4g} m/s",
          decile * 10, sim.steps_done(), sim.time(), sim.ledger().water,
          sim.diagnostics().max_depth, sim.diagnostics().max_speed);
    }
  }
  void done() const {
    if (terminal_) std::fprintf(stderr, "\n");
  }
  double elapsed() const { return seconds(Clock::now() - start_); }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
  bool terminal_;
  Clock::time_point start_, last_;
  int decile_ = 0;
};

int run(const RunOptions& o) {
  Params p = load_config(o.config);
  for (const auto& s : o.sets) apply_setting(p, s);
  if (!o.output.empty()) p.output.path = o.output;
  validate(p, o.config);
  if (o.dump_config) {
    std::fputs(dump_toml(p).c_str(), stdout);
    return 0;
  }
  if (!p.output.gauges.empty() || p.output.interval > 0 || p.output.every != Params{}.output.every)
    spdlog::warn(
        "output.every, output.interval and output.gauges take effect with the HDF5 "
        "writer; this version writes the final fields only");
  // Check every output can be created before spending time on the run.
  for (const auto& f : p.output.fields)
    check_output_path(field_path(p.output.path, f), o.overwrite);

  Simulation sim = io::make_simulation(p, o.backend);
  const auto& g = sim.grid();
  spdlog::info("erodem {}: {} ({} x {} cells, dx {:.4g} m), backend {} [{}]", ERODEM_VERSION,
               sim.terrain().source, g.nx, g.ny, g.dx_min(), sim.backend().name(),
               sim.backend().device());
  spdlog::info(
      "flow {}, erosion {}, transport {}, thermal {}, {}",
      p.flow.scheme == FlowScheme::pipes ? "pipes" : "local_inertial",
      p.erosion.enabled ? "on" : "off",
      p.transport.scheme == TransportScheme::conservative ? "conservative" : "semi_lagrangian",
      p.thermal.enabled ? "on" : "off",
      p.time.duration > 0 ? fmt::format("{:.6g} s simulated", p.time.duration)
                          : fmt::format("{} steps", p.time.steps));

  auto previous = std::signal(SIGINT, on_sigint);
  Progress progress(stderr_is_terminal());
  try {
    while (!sim.finished() && !g_interrupted) {
      sim.step();
      progress.update(sim);
    }
  } catch (...) {
    progress.done();
    std::signal(SIGINT, previous);
    throw;
  }
  progress.done();
  std::signal(SIGINT, previous);
  if (g_interrupted) {
    std::fprintf(stderr, "erodem: interrupted at step %ld (t = %.6g s); no output written\n",
                 sim.steps_done(), sim.time());
    return 130;
  }
  const double wall = progress.elapsed();
  const double cells = static_cast<double>(g.cells());
  std::printf("%s", sim.ledger().format().c_str());
  std::printf("ran %ld steps to t = %.6g s in %.3f s wall (%.3g cell-steps/s)\n", sim.steps_done(),
              sim.time(), wall, cells * sim.steps_done() / wall);
  for (const auto& name : p.output.fields) {
    const auto& info = field_info(name);
    const auto values = sim.field(info.id);
    std::vector<float> f32(values.begin(), values.end());
    for (std::size_t i = 0; i < f32.size(); ++i)
      if (!sim.terrain().active(i)) f32[i] = std::nanf("");  // nodata stays nodata
    const std::string path = field_path(p.output.path, name);
    io::write_geotiff(path, g, f32, fmt::format("{} ({})", info.long_name, info.units));
    std::printf("wrote %s\n", path.c_str());
  }
  return 0;
}

}  // namespace

Action add_run(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  auto* sub = app.add_subcommand("run", "Run an experiment from a TOML config");
  sub->add_option("config", o->config, "Config file (TOML)")->required();
  sub->add_option("--set", o->sets, "Override a config key: key=value (repeatable)");
  sub->add_option("--backend", o->backend, "Compute backend")
      ->check(CLI::IsMember({"auto", "cpu", "opencl"}));
  sub->add_option("--output", o->output, "Output path (overrides output.path)");
  sub->add_flag("--dump-config", o->dump_config, "Print the fully resolved config and exit");
  sub->add_flag("--overwrite", o->overwrite, "Replace existing output files");
  return [o] { return run(*o); };
}

}  // namespace erodem::cli
