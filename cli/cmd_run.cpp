// `erodem run CONFIG.toml`: runs an experiment and prints the mass ledger.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/results.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/schema.hpp"
#include "erodem/units.hpp"

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
  std::string restart;  ///< FILE.h5[:TIME]
};

/// `--restart FILE.h5[:TIME]` split: the file, and the time (s) if one was given.
std::pair<std::string, std::optional<double>> split_restart(const std::string& arg) {
  const auto colon = arg.rfind(':');
  if (colon != std::string::npos && colon + 1 < arg.size()) {
    if (auto t = try_parse_quantity(arg.substr(colon + 1), Dimension::time))
      return {arg.substr(0, colon), *t};
  }
  return {arg, std::nullopt};
}

/// The snapshot of `reader` at `time` (the last one when no time is given). Times match to
/// 1e-6 relative or 1 ms, since a time on a command line is rounded.
std::size_t restart_index(const io::ResultReader& reader, std::optional<double> time) {
  const auto& times = reader.times();
  if (times.empty()) throw Error(ExitCode::data, reader.path() + ": holds no snapshot");
  if (!time) return times.size() - 1;
  const std::size_t i = reader.nearest_time_index(*time);
  if (std::abs(times[i] - *time) <= std::max(1e-3, 1e-6 * std::abs(*time))) return i;
  std::string list;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (times.size() > 50 && k == 25) {  // long lists: the first and last 25
      list += ", ...";
      k = times.size() - 25;
    }
    list += fmt::format("{}{:.10g}", list.empty() ? "" : ", ", times[k]);
  }
  throw Error(ExitCode::usage, fmt::format("--restart {}:{:.10g}: no snapshot at that time; the "
                                           "file holds t = {} s",
                                           reader.path(), *time, list));
}

/// "section.key = value" of a TOML text written by dump_toml, one entry per key line.
std::map<std::string, std::string> config_entries(const std::string& toml) {
  std::map<std::string, std::string> out;
  std::istringstream in(toml);
  std::string line, section;
  std::map<std::string, int> arrays;  // [[inflow]] tables are numbered
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("[[", 0) == 0) {
      const std::string name = line.substr(2, line.find("]]") - 2);
      section = fmt::format("{}[{}]", name, arrays[name]++);
    } else if (line[0] == '[') {
      section = line.substr(1, line.find(']') - 1);
    } else if (const auto eq = line.find(" = "); eq != std::string::npos) {
      out[section + "." + line.substr(0, eq)] = line.substr(eq + 3);
    }
  }
  return out;
}

/// The keys (besides time.* and output.*, which a restart may change) whose values differ.
std::vector<std::string> changed_keys(const std::string& stored, const std::string& now) {
  const auto a = config_entries(stored), b = config_entries(now);
  std::set<std::string> keys;
  for (const auto& [k, v] : a) keys.insert(k);
  for (const auto& [k, v] : b) keys.insert(k);
  std::vector<std::string> out;
  for (const auto& k : keys) {
    if (k.rfind("time.", 0) == 0 || k.rfind("output.", 0) == 0) continue;
    const auto ia = a.find(k), ib = b.find(k);
    if (ia == a.end() || ib == b.end() || ia->second != ib->second) out.push_back(k);
  }
  return out;
}

/// Continues `sim` from the stored state `arg` = FILE.h5[:TIME]; returns "FILE:TIME".
std::string restore_from(Simulation& sim, const std::string& arg) {
  const auto [file, time] = split_restart(arg);
  const io::ResultReader reader(file);
  const auto& g = reader.grid();
  if (g.nx != sim.grid().nx || g.ny != sim.grid().ny)
    throw Error(ExitCode::data,
                fmt::format("--restart {}: the stored run is on a {} x {} grid, this config gives "
                            "{} x {}",
                            file, g.nx, g.ny, sim.grid().nx, sim.grid().ny));
  const std::size_t index = restart_index(reader, time);
  sim.restore(reader.restart_point(index));
  const auto changed = changed_keys(reader.attribute("config_toml"), dump_toml(sim.params()));
  if (!changed.empty())
    spdlog::warn("restarting with a config that differs from the stored run's in: {}",
                 fmt::join(changed, ", "));
  if (reader.attribute("backend") != sim.backend().name())
    spdlog::warn("the stored run used the {} backend, this one {}: not bit for bit",
                 reader.attribute("backend"), sim.backend().name());
  spdlog::info("restarting from {} at step {} (t = {:.10g} s)", file, sim.steps_done(), sim.time());
  return fmt::format("{}:{:.17g}", file, sim.time());
}

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
  const std::string restarted = o.restart.empty() ? "" : restore_from(sim, o.restart);
  const long first_step = sim.steps_done();
  const auto& g = sim.grid();
  spdlog::info("erodem {}: {} ({} x {} cells, dx {:.4g} m), backend {} [{}]", ERODEM_VERSION,
               sim.terrain().source, g.nx, g.ny, g.dx_min(), sim.backend().name(),
               sim.backend().device());
  spdlog::info("flow {}, erosion {}, transport {}, thermal {}, {}", scheme_name(p.flow.scheme),
               p.erosion.enabled ? "on" : "off", scheme_name(p.transport.scheme),
               p.thermal.enabled ? "on" : "off",
               p.time.duration > 0 ? fmt::format("{:.6g} s simulated", p.time.duration)
                                   : fmt::format("{} steps", p.time.steps));

  // Results go to a temporary file beside the output (flushed at every snapshot) that is
  // renamed into place when the run completes.
  io::Provenance provenance = io::Provenance::of(sim, command_line());
  provenance.restart_from = restarted;
  io::ResultWriter writer(p.output.path, sim.grid(), sim.params(), provenance, o.overwrite);
  writer.snapshot(sim);  // t = 0, or the state restarted from
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
              writer.path().c_str(), writer.snapshots(), p.output.fields.size(),
              sim.steps_done() - first_step, io::xdmf_path(writer.path()).c_str());
  // The closures last, relative to what moved (ledger.hpp), for scripts that read the tail.
  const Ledger& L = sim.ledger();
  std::printf(
      "closures: water %.3e m^3 (%.2e of %.3e m^3 moved), material %.3e m^3 (%.2e of %.3e m^3 "
      "moved)\n",
      L.closure_error(), L.relative_closure_error(), L.water_moved(), L.material_closure_error(),
      L.relative_material_closure_error(), L.material_moved());
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
  sub->add_option("--restart", o->restart,
                  "Continue a run from the state stored in FILE.h5 at TIME (s, or with a unit; "
                  "default: its last snapshot)")
      ->type_name("FILE.h5[:TIME]");
  return [o] { return run(*o); };
}

}  // namespace erodem::cli
