// erodem — result files: one HDF5 file per run that is also netCDF-4 / CF-1.8, so h5py,
// xarray (engine="h5netcdf"), GDAL/QGIS and ParaView (through the .xmf sidecar) read it
// as it is. Layout: docs/results.md and INTERFACES.md "Result files (.h5)".
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/io/paths.hpp"
#include "erodem/params.hpp"
#include "erodem/simulation.hpp"

namespace erodem::io {

/// The version and `git describe` of this build.
/// Skips HDF5's own clean-up at process exit. A result file that fails to open (a corrupt
/// one) can leave objects HDF5 cannot close, and that clean-up then prints "HDF5: infinite
/// loop closing library" and a page-long line after erodem's one-line error. Every file erodem
/// writes is closed explicitly before. Call it first in main, before any other HDF5 call.
void skip_hdf5_exit_cleanup();

std::string build_version();
std::string build_git_describe();

/// Where a result file and its inputs came from; written as root attributes.
struct Provenance {
  std::string erodem_version = build_version();
  std::string git_describe = build_git_describe();
  std::string command_line;
  std::string config_toml;  ///< the fully resolved config (dump_toml)
  std::string backend;
  std::string device;
  std::string backend_reason;  ///< why that backend (Backend::choice_reason)
  std::string dem_path;        ///< DEM file, or the generator description
  std::string dem_sha256;      ///< SHA-256 of the DEM file ("" for synthetic terrain)
  std::string restart_from;    ///< "FILE:TIME" a restarted run continued from ("" otherwise)

  /// Everything but `command_line` from a simulation (config from its params).
  static Provenance of(const Simulation& sim, const std::string& command_line);
};

/// The temporary name a result file is written under until ResultWriter::finish(), unique
/// to this process: "dir/run.h5" -> "dir/.run.h5.HOST-PID.partial" (host_name(), getpid()).
std::string partial_path(const std::string& path);
/// Removes the partial files of `path` left by processes of this host that have ended
/// (".run.h5.HOST-PID.partial" whose PID does not exist); those of other hosts stay.
void remove_stale_partials(const std::string& path);
/// Whether this build writes an MPI run's result file with parallel HDF5
/// (ERODEM_PARALLEL_HDF5: CMake found the MPI build of HDF5, Debian's libhdf5-openmpi-dev).
bool built_with_parallel_hdf5();
/// Whether the ranks of this MPI run write one result file together: a build with parallel
/// HDF5 (ERODEM_PARALLEL_HDF5) and more than one rank (docs/mpi.md). Every rank then runs the
/// same ResultWriter calls on rank 0's partial file, each writing the rows of its band, and
/// rank 0 renames it into place; otherwise each process writes a file of its own.
bool collective_files();
/// The XDMF sidecar of a result file: "dir/run.h5" -> "dir/run.xmf".
std::string xdmf_path(const std::string& path);

/// Writes one run's result file.
///
/// The file is written under partial_path(path) and renamed to `path` by finish(); it is
/// flushed after every snapshot, so a run that stops early (crash, unstable run, no
/// finish()) leaves a readable partial file holding every snapshot, and every diagnostics
/// row up to the last snapshot. The destructor closes the file without renaming it.
///
/// Errors: `path` exists and `overwrite` is false -> Error(ExitCode::cant_create, "...
/// exists; give --overwrite ..."); the folder is missing or not writable ->
/// Error(ExitCode::cant_create); a write that fails -> Error(ExitCode::io); a gauge outside
/// the grid -> Error(ExitCode::config) naming output.gauges[i]; an unknown field name ->
/// Error(ExitCode::config).
class ResultWriter {
 public:
  /// A writer for runs on `grid` with `params` (output.fields, output.gauges, output.every
  /// and output.interval are used).
  ResultWriter(const std::string& path, const Grid& grid, const Params& params,
               const Provenance& provenance, bool overwrite);
  /// A writer for `sim`'s grid and parameters, provenance from the simulation.
  ResultWriter(const std::string& path, const Simulation& sim, const std::string& command_line,
               bool overwrite);
  ~ResultWriter();
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  /// Appends the configured output fields at the simulation's current time (inactive cells
  /// NaN), the restart state at every output.restart_every-th snapshot (the first, t = 0,
  /// included), writes the buffered diagnostics and gauge rows, and flushes the file.
  void snapshot(const Simulation& sim);
  /// Buffers one row of diagnostics (and gauge samples) after a step of `sim`. The gauges
  /// read gauge_fields() at gauge_cells(): the step's probe samples when `sim` has them as
  /// its probes (Simulation::set_probes, as RunSession registers them), else
  /// Simulation::sample(); no whole field is copied. Level (bed + depth) and speed are
  /// double arithmetic here.
  void record_step(const Simulation& sim);
  /// The DEM cells of output.gauges (row * nx + col, in order) and the fields record_step
  /// reads there (water_depth, velocity_x, velocity_y, and the bed where a sweep of the step
  /// writes it; a fixed bed is sampled once): the probes to register with the simulation.
  /// Empty once the file is closed.
  const std::vector<std::int64_t>& gauge_cells() const;
  const std::vector<FieldId>& gauge_fields() const;
  /// Whether output.every / output.interval ask for a snapshot at `sim`'s current step
  /// (never twice for the same step).
  bool snapshot_due(const Simulation& sim) const;
  /// record_step(), then snapshot() when due.
  void step_done(const Simulation& sim);
  /// The run's last snapshot: a snapshot of `sim`'s current step unless it has one, and
  /// with the restart state (output.restart_state) whatever output.restart_every says.
  void last_snapshot(const Simulation& sim);
  /// last_snapshot(), then finish().
  void finish(const Simulation& sim);
  /// Writes what is buffered, closes the file, renames it into place (publish()) and writes
  /// the .xmf sidecar.
  void finish();
  /// Renames the closed partial file to path(), never over a file another process put there
  /// during the run: without `overwrite` nothing may be at path() (renameat2
  /// RENAME_NOREPLACE, or link + unlink where the file system refuses it: rename_no_replace;
  /// `force_link` takes that way, for the tests), with it only the file that was there when
  /// the writer was made (same device, inode, mtime and size) or nothing. Otherwise
  /// Error(ExitCode::cant_create) naming path() and partial(), which keeps the results.
  void publish(bool force_link = false) const;
  /// Writes what is buffered and closes the file without renaming it: it stays at
  /// partial(), a readable result file (as the destructor leaves it). No-op once closed.
  void close();
  /// Whether the file is open (not finished or closed yet).
  bool is_open() const { return static_cast<bool>(impl_); }

  const std::string& path() const { return path_; }
  /// Where the file is until finish().
  const std::string& partial() const { return partial_; }
  std::size_t snapshots() const { return times_.size(); }
  /// The snapshots stored with their restart state (output.restart_every).
  std::size_t states() const { return states_; }
  /// Step of the last snapshot (-1 before the first).
  long last_snapshot_step() const { return last_snapshot_step_; }

 private:
  void take_snapshot(const Simulation& sim, bool last);
  void store_state(const Simulation& sim);  // one row of restart/

  struct Impl;
  std::string path_, partial_;
  bool overwrite_;
  FileIdentity seen_;  // the file at path_ when the writer was made
  std::unique_ptr<Impl> impl_;
  std::vector<double> times_;
  std::size_t states_ = 0;
  long last_snapshot_step_ = -1;
};

/// Per-gauge series of a result file.
struct GaugeSeries {
  std::vector<double> x, y;  ///< gauge coordinates (CRS)
  std::vector<double> time;  ///< s, one per step
  /// [step][gauge]
  std::vector<std::vector<double>> water_depth, water_level, speed;
};

/// Reads a result file written by ResultWriter (also a partial one).
///
/// Missing file -> Error(ExitCode::no_input); not an HDF5 file or not this layout ->
/// Error(ExitCode::data).
class ResultReader {
 public:
  explicit ResultReader(const std::string& path);
  ~ResultReader();
  ResultReader(const ResultReader&) = delete;
  ResultReader& operator=(const ResultReader&) = delete;

  /// The fields stored, in file order.
  std::vector<std::string> fields() const;
  /// Snapshot times (s since the start of the run).
  const std::vector<double>& times() const { return times_; }
  /// The index of the snapshot time nearest `time`.
  std::size_t nearest_time_index(double time) const;
  /// Field `name` at snapshot `index` (row-major ny x nx, NaN = nodata). Unknown field ->
  /// Error(ExitCode::data); index out of range -> Error(ExitCode::usage).
  std::vector<float> read_index(const std::string& name, std::size_t index) const;
  /// Field `name` at the snapshot nearest `time` (s).
  std::vector<float> read(const std::string& name, double time) const;
  /// The grid: size, geotransform (from the GeoTransform attribute, else the x/y
  /// coordinates), CRS (WKT) and the per-row cell sizes and areas (m, m^2) as written.
  const Grid& grid() const { return grid_; }
  /// The per-step diagnostics.
  std::vector<Diagnostics> diagnostics() const;
  /// Whether the file holds the full state at some snapshots (output.restart_state).
  bool has_restart_state() const;
  /// The times whose full state the file holds (s; restart/time, every
  /// output.restart_every-th snapshot and the last; in files before 2026-11-27 every
  /// snapshot); empty without restart state.
  std::vector<double> restart_times() const;
  /// The full state at restart_times()[index], to continue the run from
  /// (Simulation::restore). No restart state -> Error(ExitCode::data) saying how to get one;
  /// index out of range -> Error(ExitCode::usage). Reads both layouts: restart/time with
  /// once-per-value fields (NAME_row), and the older one, a row per snapshot.
  RestartPoint restart_point(std::size_t index) const;
  /// restart_point(index) without its fields (time, steps, ledger), after checking that every
  /// state field's dataset is there and fits the grid (the errors restart_point gives), to
  /// read them a strip at a time with restart_rows (Simulation::restore: no whole field).
  RestartPoint restart_header(std::size_t index) const;
  /// Rows [row0, row1) of state field `id` at restart_times()[index], row-major ((row1 - row0),
  /// nx): those rows of restart_point(index)'s field, the same values.
  std::vector<double> restart_rows(std::size_t index, FieldId id, int row0, int row1) const;
  /// Gauge series (empty when the run had none).
  GaugeSeries gauges() const;
  /// Root attributes (text), e.g. "config_toml", "erodem_version", "created".
  const std::map<std::string, std::string>& attributes() const { return attributes_; }
  /// One root attribute; "" when absent.
  std::string attribute(const std::string& name) const;
  const std::string& path() const { return path_; }

 private:
  std::int64_t file_ = -1;
  std::string path_;
  std::vector<double> times_;
  Grid grid_;
  std::map<std::string, std::string> attributes_;
};

}  // namespace erodem::io
