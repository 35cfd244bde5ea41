// `erodem run CONFIG.toml`: runs an experiment and prints the mass ledger.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/results.hpp"
#include "erodem/io/run_session.hpp"
#include "erodem/parallel.hpp"
#include "erodem/schema.hpp"

namespace erodem::cli {

namespace {

/// A request to stop: Ctrl-C (SIGINT), SIGTERM (a batch system's time limit, `kill`) or
/// SIGUSR1 (`kill -USR1`; OpenMPI 4.1's mpirun does not pass it on to the ranks). The first
/// finishes the step and stores it; in one process a second of the same signal takes that
/// signal's default action (ends the process). Under MPI a rank may get a signal twice (from
/// the batch system and from mpirun), so there it stays caught until the ranks have agreed.
std::atomic<bool> g_interrupted{false};
std::atomic<bool> g_second_ends{true};
extern "C" void on_stop_signal(int sig) {
  g_interrupted = true;
  if (g_second_ends) std::signal(sig, SIG_DFL);
}
constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGUSR1};

struct RunOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string backend = "auto";
  std::string output;
  bool output_given = false;  ///< --output on the command line (an empty one is refused)
  bool dump_config = false;
  bool overwrite = false;
  std::string restart;  ///< FILE.h5[:TIME]
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

/// Where a rank of an MPI run other than 0 writes its result file in a build without parallel
/// HDF5: a fresh directory in the temporary directory, removed with this (docs/mpi.md: every
/// rank runs the writer, whose reads of the fields gather them from all ranks; rank 0's file
/// is the result).
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    const std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
    if (ec) {
      const char* env = std::getenv("TMPDIR");
      throw Error(ExitCode::cant_create,
                  fmt::format("MPI rank {}: no temporary directory for its scratch file "
                              "(TMPDIR={}): {}",
                              parallel::rank(), env ? env : "(unset)", ec.message()));
    }
    std::string name = (tmp / "erodem-rank-XXXXXX").string();
    if (!mkdtemp(name.data()))
      throw Error(ExitCode::cant_create,
                  fmt::format("MPI rank {}: cannot create a scratch directory {}: {}",
                              parallel::rank(), name, std::strerror(errno)));
    path_ = name;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

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
  // under mpirun, each process a rank of the one run (docs/mpi.md); other commands are not
  parallel::decompose();
  Params p = load_config(o.config);
  for (const auto& s : o.sets) apply_setting(p, s);
  if (o.output_given) {
    if (o.output.empty())
      throw Error(ExitCode::usage,
                  "--output: an empty path; give a file name, or leave --output out to write "
                  "to output.path");
    p.output.path = o.output;
  }
  validate(p, o.config);
  if (!parallel::built_with_mpi() && parallel::launched_size() > 1)
    throw Error(ExitCode::usage,
                fmt::format("started by mpirun as one of {} processes, but this erodem was built "
                            "without MPI (ERODEM_MPI off): each would run the whole grid into the "
                            "same output; rebuild with MPI (docs/mpi.md) or run one process",
                            parallel::launched_size()));
  // MPI (docs/mpi.md): rank 0 reports; every rank writes the one result file with parallel
  // HDF5 (io::collective_files), or, in a build with serial HDF5 only, rank 0 writes it and the
  // others run the same session quietly into a scratch file.
  const bool root = parallel::rank() == 0;
  std::optional<ScratchDir> scratch;
  if (!root) {
    if (!io::collective_files()) {
      scratch.emplace();
      p.output.path = (scratch->path() / std::filesystem::path(p.output.path).filename()).string();
    }
    spdlog::set_level(spdlog::level::off);
  }
  if (o.dump_config) {
    if (!root) return 0;
    std::fputs(dump_toml(p).c_str(), stdout);
    return 0;
  }
  // The run driver (io/run_session.hpp): checks that the output can be created before
  // reading the inputs, builds the simulation, continues the stored run of --restart, and
  // opens the result file with its first snapshot (t = 0, or the state restarted from).
  io::SessionOptions options;
  options.backend = o.backend;
  options.command_line = command_line();
  options.restart = o.restart;
  options.overwrite = o.overwrite;
  options.on_built = [&](const io::RunSession& s) {  // before the result file is opened
    const Simulation& sim = s.sim();
    for (const auto& w : s.warnings()) spdlog::warn("{}", w);
    if (!s.restart_from().empty())
      spdlog::info("restarting from {} at step {} (t = {:.10g} s)",
                   io::split_restart(o.restart).first, sim.steps_done(), sim.time());
    const auto& g = sim.grid();
    spdlog::info("erodem {}: {} ({} x {} cells, dx {:.4g} m), backend {} [{}]", ERODEM_VERSION,
                 sim.terrain().source, g.nx, g.ny, g.dx_min(), sim.backend().name(),
                 sim.backend().device());
    spdlog::info("backend chosen by {}", sim.backend().choice_reason());
    for (const auto& note : sim.setup_notes()) spdlog::info("{}", note);
    for (const auto& warning : sim.setup_warnings()) spdlog::warn("{}", warning);
    spdlog::info("flow {}, erosion {}, transport {}, thermal {}, {}", scheme_name(p.flow.scheme),
                 p.erosion.enabled ? "on" : "off", scheme_name(p.transport.scheme),
                 p.thermal.enabled ? "on" : "off",
                 p.time.duration > 0 ? fmt::format("{:.6g} s simulated", p.time.duration)
                                     : fmt::format("{} steps", p.time.steps));
  };
  io::RunSession session(p, options);
  const Simulation& sim = session.sim();
  const auto& g = sim.grid();

  g_second_ends = parallel::size() <= 1;
  std::vector<void (*)(int)> previous;
  for (const int sig : kStopSignals) previous.push_back(std::signal(sig, on_stop_signal));
  const auto restore_signals = [&previous] {
    for (std::size_t k = 0; k < previous.size(); ++k) std::signal(kStopSignals[k], previous[k]);
  };
  Progress progress(root && stderr_is_terminal());
  io::Stop stop = io::Stop::finished;
  try {
    // To the configured end, or a stop signal; an unstable step throws with the partial-file
    // note. Under MPI the ranks stop at the same step: a signal may reach one rank a step
    // before another, so before each step they ask whether any rank has one (parallel::any).
    stop = session.advance(
        {}, [] { return parallel::any(g_interrupted.load()); },
        [&](const Simulation& s) { progress.update(s); });
  } catch (...) {
    progress.done();
    restore_signals();
    throw;
  }
  progress.done();
  // (and one signal after the last step's question: every rank again decides alike)
  const bool interrupted = stop == io::Stop::interrupted || parallel::any(g_interrupted.load());
  if (interrupted && parallel::size() > 1) {
    // Under MPI: once one rank exits (130), mpirun ends the others with SIGTERM, which must
    // not cut short their own way to exit 130 (the writer's close below is collective, so
    // they are at most a moment behind): the stop signals stay ignored from here.
    for (const int sig : kStopSignals) std::signal(sig, SIG_IGN);
  } else {
    restore_signals();
  }
  if (interrupted) {
    session.abandon();  // a snapshot of the step reached; the file stays .partial
    if (root)
      std::fprintf(stderr, "erodem: interrupted at step %ld (t = %.6g s); %s\n", sim.steps_done(),
                   sim.time(), session.partial_note().c_str());
    return 130;
  }
  session.finish();
  if (!root) return 0;
  const io::ResultWriter& writer = *session.writer();
  const double wall = progress.elapsed();
  const double cells = static_cast<double>(g.cells());
  // The backend and device on stdout too, so a saved result names what computed it (the
  // HDF5 writer records them as the root attributes `backend` and `device`).
  std::printf("backend %s, device %s\n", sim.backend().name().c_str(),
              sim.backend().device().c_str());
  std::printf("%s", sim.ledger().format().c_str());
  if (p.erosion.enabled && p.erosion.law == ErosionLaw::physical) {
    // the solid volumes as masses, and the yield over the active area (docs/model.md 3.5)
    const double area = sim.active_area();
    const Ledger& L = sim.ledger();
    const double tonnes = p.erosion.sediment_density / 1000.0;
    std::printf(
        "sediment (solid, rho_s %.0f kg/m^3): eroded %.4g t (%.4g t from bedrock), deposited "
        "%.4g t, out %.4g t = %.4g t/km^2 over %.4g km^2\n",
        p.erosion.sediment_density, L.eroded * tonnes, L.eroded_bedrock * tonnes,
        L.deposited * tonnes, L.sediment_out * tonnes, L.sediment_out * tonnes / (area * 1e-6),
        area * 1e-6);
  }
  // The cross-sections and outlets: peak discharge and when, the volumes through them.
  for (std::size_t k = 0; k < sim.sections().size(); ++k) {
    const SectionState& st = sim.sections()[k];
    std::printf(
        "%s %s: peak %.4g m^3/s at t = %.6g s, volume %.6g m^3, sediment %.4g m^3 (solid)\n",
        sim.section_layout().outlet[k] ? "outlet" : "section",
        sim.section_layout().names[k].c_str(), st.peak_discharge, st.peak_time, st.volume,
        st.sediment_volume);
  }
  // the steps this process ran (a restart's restored steps are not this run's work)
  const long ran = sim.steps_done() - session.first_step();
  std::printf("ran %ld steps to t = %.6g s in %.3f s wall (%.3g cell-steps/s)\n", ran, sim.time(),
              wall, cells * static_cast<double>(ran) / wall);
  // the file's size, and per snapshot (the restart state is most of it: output.restart_state,
  // at every output.restart_every-th snapshot and the last)
  const std::string with_state =
      !p.output.restart_state ? ""
      : writer.states() == writer.snapshots()
          ? " with the restart state"
          : fmt::format(" with the restart state at {} of them", writer.states());
  std::error_code size_error;
  const double megabytes =
      static_cast<double>(std::filesystem::file_size(writer.path(), size_error)) / 1e6;
  std::printf(
      "wrote %s (%zu snapshots of %zu fields, diagnostics of %ld steps; %.4g MB, %.3g MB "
      "per snapshot%s) and %s\n",
      writer.path().c_str(), writer.snapshots(), p.output.fields.size(), ran,
      size_error ? 0.0 : megabytes,
      size_error || writer.snapshots() == 0 ? 0.0 : megabytes / writer.snapshots(),
      with_state.c_str(), io::xdmf_path(writer.path()).c_str());
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
  sub->add_option("--output", o->output, "Output path (overrides output.path)")
      ->each([o](const std::string&) { o->output_given = true; });
  sub->add_flag("--dump-config", o->dump_config, "Print the fully resolved config and exit");
  sub->add_flag("--overwrite", o->overwrite, "Replace existing output files");
  sub->add_option("--restart", o->restart,
                  "Continue a run from the state stored in FILE.h5 at TIME (s, or with a unit; "
                  "default: its last snapshot)")
      ->type_name("FILE.h5[:TIME]");
  return [o] { return run(*o); };
}

}  // namespace erodem::cli
