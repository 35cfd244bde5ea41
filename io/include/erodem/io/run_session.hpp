// erodem — the one run driver: builds a simulation from validated parameters (or continues a
// stored run), writes its result file, and steps it with the unstable-run, interrupt and
// finish handling written once. `erodem run` (cli/cmd_run.cpp) and the Python
// `erodem.Simulation` (python/src/simulation.cpp) are thin over it, so their result files
// are identical by construction (docs/architecture.md "The run driver").
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/io/results.hpp"
#include "erodem/params.hpp"
#include "erodem/simulation.hpp"

namespace erodem::io {

class RunSession;

/// How a RunSession is built.
struct SessionOptions {
  std::string backend = "auto";  ///< "auto", "cpu" or "opencl" (make_backend)
  std::string command_line;      ///< recorded in result files (root attribute command_line)
  /// "FILE.h5[:TIME]": continue the run stored in FILE.h5 from its snapshot at TIME (s, or
  /// with a unit: "2min"; default the last snapshot). Empty: start at t = 0.
  std::string restart;
  /// How errors about `restart` name it: "--restart" on the command line, "restart" in Python.
  std::string restart_label = "--restart";
  /// Replace an existing output.path (else Error(ExitCode::cant_create)).
  bool overwrite = false;
  /// Open the result file at output.path in the constructor (after checking, before the DEM
  /// is read, that it can be created) and take its first snapshot. Without it, a file is
  /// opened later by open_output(), or none is written.
  bool write = true;
  /// A terrain already loaded for these parameters' dem.* settings (Python's read_dem), used
  /// as it is unless parameter rasters must be read on its grid (then the DEM is read again).
  /// Null: io::load_terrain.
  const Terrain* terrain = nullptr;
  /// Called once the simulation is built (and restored), before the result file is opened:
  /// where the command line logs what it runs, and reports warnings() (may be empty).
  std::function<void(const RunSession&)> on_built;
};

/// What advance() may run: it stops at the first limit reached. The defaults run to the
/// configured end.
struct Limits {
  long max_steps = std::numeric_limits<long>::max();            ///< steps in this call
  double until_time = std::numeric_limits<double>::infinity();  ///< s: stop once time >= it
  bool to_end = true;  ///< stop at the configured end (time.steps / time.duration)
  /// Wall time (s) after which this call returns (after at least one step): the chunk of a
  /// caller that must look up now and then (Python: signals, the progress bar).
  double wall_seconds = std::numeric_limits<double>::infinity();
};

/// Why advance() returned. Before every step it asks, in this order: `interrupted()`, the
/// configured end (with Limits::to_end), max_steps and until_time, wall_seconds.
enum class Stop {
  interrupted,  ///< the `interrupted` callback said so
  finished,     ///< the configured end is reached
  limit,        ///< max_steps or until_time
  wall,         ///< wall_seconds passed (more steps may remain)
};

/// One run: the simulation, where it started from, and its result file.
///
/// Errors: those of io::load_terrain / make_backend (config 78, data 65, no_input 66,
/// usage 2), of the restart (the file missing: no_input; no snapshot at TIME, the stored
/// times listed: usage; no restart state, another grid: data), of ResultWriter (cant_create
/// 73, io 74, a gauge outside the grid: config), and from advance() the unstable step
/// (Error(ExitCode::unstable), its message ending with where the results so far are).
class RunSession {
 public:
  /// Builds the simulation of `params` (validated), restores the stored state of
  /// `options.restart`, calls `options.on_built`, and with `options.write` opens the result
  /// file at output.path with its first snapshot (t = 0, or the state restarted from).
  RunSession(Params params, SessionOptions options);
  ~RunSession();
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  /// Opens a result file for the run from its current state on, with the output.* settings
  /// of `output_params` (the simulation's parameters with other output settings; its
  /// config_toml is recorded), replacing an existing file when `overwrite`; takes the first
  /// snapshot. A file still open is closed first, left at its partial name.
  void open_output(const Params& output_params, bool overwrite);

  /// Steps until a limit, the configured end, or `interrupted()` (asked before every step;
  /// may be empty). After every step: the result file's diagnostics row and snapshot when due,
  /// then `on_step(sim)` (may be empty). An unstable step (Error(ExitCode::unstable)) is
  /// recorded in the result file (its diagnostics row and a snapshot of its state, NaNs
  /// included) and rethrown with partial_note() appended. With no step allowed (a limit
  /// already reached) it returns at once.
  Stop advance(const Limits& limits = {}, const std::function<bool()>& interrupted = {},
               const std::function<void(const Simulation&)>& on_step = {});

  /// The end of a complete run: the last snapshot (unless this step has one), the .xmf
  /// sidecar, and the rename of the partial file into place. No-op without a result file.
  void finish();
  /// The end of a run stopped early (Ctrl-C): a snapshot of the current state (unless this
  /// step has one) and the file closed at its partial name. No-op without a result file.
  void abandon();
  /// Closes the result file as it is, at its partial name (after an error).
  void close_output();

  Simulation& sim() { return *sim_; }
  const Simulation& sim() const { return *sim_; }
  /// The result file of this session: the last one opened, also once finished or closed
  /// (path(), partial(), snapshots()); null when none was opened.
  const ResultWriter* writer() const { return writer_.get(); }
  /// Whether a result file is open (advance() writes to it).
  bool writing() const;
  /// "FILE:TIME" of the state this run continued from; "" when it started at t = 0.
  const std::string& restart_from() const { return restart_from_; }
  /// Things the caller should tell the user: a restart with a config or backend other than
  /// the stored run's (no longer bit for bit).
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Steps done when the session was built (0, or the step restarted from).
  long first_step() const { return first_step_; }
  /// "the results up to step N (t = T s) are in PARTIAL; PATH was not created".
  std::string partial_note() const;

 private:
  void restore(const std::string& arg);
  SessionOptions options_;
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<ResultWriter> writer_;
  std::string restart_from_;
  std::vector<std::string> warnings_;
  long first_step_ = 0;
};

/// `FILE.h5[:TIME]` split into the file and the time (s) when one was given: the text after
/// the last ':' when it reads as a time ("600", "10 min"), else the whole is the file.
std::pair<std::string, std::optional<double>> split_restart(const std::string& arg);

/// The fully resolved config a result file was written with (its root attribute
/// config_toml), as parameters: the base of a restart given without a config. Errors as
/// ResultReader; a file without the attribute -> Error(ExitCode::data).
Params stored_params(const std::string& restart_arg);

}  // namespace erodem::io
