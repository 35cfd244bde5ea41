// `erodem run CONFIG.toml`: runs an experiment and prints the mass ledger.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/results.hpp"
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

/// This process's command line (recorded in the result file), arguments quoted for a shell
/// where needed.
std::string command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string line, arg;
  auto flush = [&] {
    const bool plain =
        !arg.empty() && arg.find_first_of(" \t\n'\"\\$`*?;&|<>()[]{}") == std::string::npos;
    if (!line.empty()) line += ' ';
    if (plain) {
      line += arg;
    } else {
      line += '\'';
      for (char c : arg) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
      line += '\'';
    }
    arg.clear();
  };
  for (char c : raw) {
    if (c == '\0')
      flush();
    else
      arg += c;
  }
  if (!arg.empty()) flush();
  return line;
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
  // Check the output can be created before reading the inputs.
  check_output_path(p.output.path, o.overwrite);

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

  // Results go to a temporary file beside the output (flushed at every snapshot) that is
  // renamed into place when the run completes.
  io::ResultWriter writer(p.output.path, sim, command_line(), o.overwrite);
  writer.snapshot(sim);  // t = 0
  const auto partial_note = [&] {
    return fmt::format("the results up to step {} (t = {:.6g} s) are in {}; {} was not created",
                       sim.steps_done(), sim.time(), writer.partial(), writer.path());
  };

  auto previous = std::signal(SIGINT, on_sigint);
  Progress progress(stderr_is_terminal());
  try {
    while (!sim.finished() && !g_interrupted) {
      sim.step();
      writer.step_done(sim);  // diagnostics every step, snapshots as configured
      progress.update(sim);
    }
  } catch (const Error& e) {
    progress.done();
    std::signal(SIGINT, previous);
    if (e.code() != ExitCode::unstable) throw;
    // Keep the failing step (its diagnostics and state) for inspection.
    try {
      writer.record_step(sim);
      writer.snapshot(sim);
    } catch (const Error&) {  // the partial file keeps the earlier snapshots
    }
    throw Error(e.code(), std::string(e.what()) + "; " + partial_note());
  } catch (...) {
    progress.done();
    std::signal(SIGINT, previous);
    throw;
  }
  progress.done();
  std::signal(SIGINT, previous);
  if (g_interrupted) {
    writer.snapshot(sim);
    std::fprintf(stderr, "erodem: interrupted at step %ld (t = %.6g s); %s\n", sim.steps_done(),
                 sim.time(), partial_note().c_str());
    return 130;
  }
  writer.finish(sim);
  const double wall = progress.elapsed();
  const double cells = static_cast<double>(g.cells());
  // The backend and device on stdout too, so a saved result names what computed it (the
  // HDF5 writer records them as the root attributes `backend` and `device`).
  std::printf("backend %s, device %s\n", sim.backend().name().c_str(),
              sim.backend().device().c_str());
  std::printf("%s", sim.ledger().format().c_str());
  std::printf("ran %ld steps to t = %.6g s in %.3f s wall (%.3g cell-steps/s)\n", sim.steps_done(),
              sim.time(), wall, cells * sim.steps_done() / wall);
  std::printf("wrote %s (%zu snapshots of %zu fields, diagnostics of %ld steps) and %s\n",
              writer.path().c_str(), writer.snapshots(), p.output.fields.size(), sim.steps_done(),
              io::xdmf_path(writer.path()).c_str());
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
