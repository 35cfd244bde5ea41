// erodem — the simulation driver: runs a backend through the step sequence, chooses the
// time step, keeps the ledger and stops an unstable run with the step and the cell.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "erodem/backend.hpp"
#include "erodem/band_series.hpp"
#include "erodem/grid.hpp"
#include "erodem/ledger.hpp"
#include "erodem/params.hpp"
#include "erodem/sections.hpp"

namespace erodem {

/// Value of a piecewise-linear series at time t (s); held constant beyond its ends.
double series_value(const Series& s, double t);
/// The largest value of the series (as series_value) over the times [t0, t1] (s).
double series_max(const Series& s, double t0, double t1);

/// One row of the per-step diagnostics (HDF5 `diagnostics/`).
struct Diagnostics {
  double time = 0.0;  ///< s, at the end of the step
  double dt = 0.0;    ///< s
  double water_volume = 0.0, material_volume = 0.0;
  double rain_volume = 0.0, inflow_volume = 0.0, boundary_outflow_volume = 0.0;
  double evaporated_volume = 0.0, closure_error = 0.0;
  double max_depth = 0.0, max_speed = 0.0;
  double eroded_volume = 0.0, deposited_volume = 0.0;  ///< cumulative (m^3)
  double material_closure_error = 0.0;                 ///< m^3
  double relative_closure_error = 0.0;                 ///< 1, of the water moved
  double relative_material_closure_error = 0.0;        ///< 1, of the material moved
};

/// One series of the per-step diagnostics: its name (HDF5 `diagnostics/<name>`, a Python
/// diagnostics key), member, units (UDUNITS) and long name.
struct DiagnosticsSeries {
  const char* name;
  double Diagnostics::*member;
  const char* units;
  const char* long_name;
};

/// Every series of the diagnostics, in file order.
const std::array<DiagnosticsSeries, 16>& diagnostics_series();

/// The state of a run between two steps: with the same terrain and parameters, a run
/// restored from it continues exactly as the uninterrupted run would (same backend and
/// precision: bit for bit).
struct RestartPoint {
  double time = 0.0;  ///< s since the start of the run
  long steps = 0;     ///< steps done
  Ledger ledger;
  /// Values of state_fields(), in that order, each row-major (ny, nx).
  std::vector<std::vector<double>> fields;
};

class Simulation {
 public:
  /// Takes the host inputs, the validated parameters and the backend that holds the state
  /// (built from the same terrain and parameters). Throws erodem::Error on inputs that
  /// cannot run (e.g. an inflow outside the active cells).
  Simulation(Terrain terrain, Params params, std::unique_ptr<Backend> backend);

  /// Runs one step of the sequence. Throws erodem::Error(ExitCode::unstable) naming the
  /// step, time and cell when the state turns NaN, negative or violates the CFL bound.
  void step();
  /// Runs `n` steps.
  void step(long n);
  /// Whether the configured end (time.steps or time.duration) is reached.
  bool finished() const;
  /// Runs to the configured end; `on_step` (optional) is called after every step.
  void run(const std::function<void(const Simulation&)>& on_step = {});

  /// The state now, to continue from later (copies every state field from the backend).
  RestartPoint restart_point() const;
  /// Continues from `point` (taken from a run with this terrain and these parameters):
  /// sets the backend's state fields, the time, the step count and the ledger. Throws
  /// Error(ExitCode::data) when the point does not fit the grid.
  void restore(const RestartPoint& point);
  /// Rows [row0, row1) of a state field, row-major ((row1 - row0), nx): a restart state read
  /// a strip at a time (io::ResultReader::restart_rows).
  using StateRows = std::function<std::vector<double>(FieldId id, int row0, int row1)>;
  /// Continues from `header` (a RestartPoint without fields: time, steps, ledger) with each
  /// state field given by `rows` a strip of kRestoreStrip rows at a time (the result files'
  /// chunk height: io/src/result_writer.cpp kChunkSide), only the strips of
  /// the rows the terrain holds (an MPI rank's band), so no state field of the whole grid is
  /// held (19 of them in double were 152 B per cell of the grid on every rank). The same
  /// state as restore() with the whole fields.
  void restore(const RestartPoint& header, const StateRows& rows);
  static constexpr int kRestoreStrip = 512;

  /// The time step the next step will take (s).
  double next_dt() const;

  /// What the setup decided that the log should say, one line each: the terrain's notes
  /// (Terrain::notes) and whether the east and west edges are joined (boundary.periodic_x).
  const std::vector<std::string>& setup_notes() const { return notes_; }
  /// What the log should warn of: on a lat/lon grid whose narrowest cells (near a pole) are
  /// under half as wide as its widest, their latitude, width and time step limit against the
  /// widest's, and boundary.latitude_cap.
  const std::vector<std::string>& setup_warnings() const { return warnings_; }

  /// Tells the simulation that its state was changed outside step(): the statistics the
  /// next time step is chosen from (and the stability check) are taken again before they
  /// are used. backend() (non-const) calls it, since whoever holds the backend may change
  /// the state (Backend::set_field, or a host view written in place before the next step).
  void state_changed() {
    stale_ = true;
    probes_current_ = false;
  }

  /// Registers the probes every step samples (Backend::set_probes): `fields` at the DEM
  /// cells `cells` (row * nx + col), gathered with the step's statistics (on OpenCL on the
  /// device, in the step's one read). Replaces the earlier ones; empty lists: none.
  void set_probes(const std::vector<std::int64_t>& cells, const std::vector<FieldId>& fields);
  const std::vector<std::int64_t>& probe_cells() const { return probe_cells_; }
  const std::vector<FieldId>& probe_fields() const { return probe_fields_; }
  /// The probes at the end of the latest step, probe_fields() by probe_cells()
  /// (StepResult::probes), each as field(id)[cell] gives it; null when no step has run since
  /// set_probes(), or the state changed since the step (state_changed(), restore()).
  const std::vector<double>* probes() const { return probes_current_ ? &probes_ : nullptr; }
  /// Field `id` at the DEM cells `cells` now, as field(id)[cell] gives it, without reading
  /// the whole field (Backend::sample).
  std::vector<double> sample(const std::vector<std::int64_t>& cells, FieldId id) const {
    return backend_->sample(cells, id);
  }

  /// The faces of the cross-sections and outlets (params' [[section]], [[outlet]]).
  const SectionLayout& section_layout() const { return sections_; }
  /// Each section's and outlet's measure after the latest step (section_layout().names'
  /// order): what the step's water update and transport moved through its faces, summed in
  /// double in face order, and the running volumes and peak. All 0 before the first step.
  const std::vector<SectionState>& sections() const { return section_state_; }
  double time() const { return time_; }
  long steps_done() const { return steps_; }
  const Ledger& ledger() const { return ledger_; }
  const Diagnostics& diagnostics() const { return diag_; }
  const FieldStats& last_stats() const { return current_stats(); }
  const Params& params() const { return params_; }
  /// The grid, mask, source and notes of the terrain it was made from; its per-cell inputs
  /// (the bed, the rasters, the bands) are freed once the backend holds them
  /// (Terrain::release_cell_inputs): read the state through field(). Under MPI with a terrain
  /// read by rows (Terrain::banded) its mask is the band's rows': ask terrain_rows.hpp about
  /// other cells.
  const Terrain& terrain() const { return terrain_; }
  const Grid& grid() const { return terrain_.grid; }
  /// The area of the active cells (m^2), summed in row-major order on every rank.
  double active_area() const { return active_area_; }
  /// The backend, to change the state with: the statistics are taken again before the next
  /// step (state_changed()).
  Backend& backend() {
    state_changed();
    return *backend_;
  }
  const Backend& backend() const { return *backend_; }
  /// A field, row-major (ny, nx), in SI units.
  std::vector<double> field(FieldId id) const { return backend_->field(id); }
  /// Rows [row0, row1) of field(id) (Backend::field_rows): a field a strip at a time.
  std::vector<double> field_rows(FieldId id, int row0, int row1) const {
    return backend_->field_rows(id, row0, row1);
  }
  /// The rows of field_rows(id, row0, row1) this process computes (Backend::own_field_rows):
  /// an MPI band's own rows, all of them in one process; no communication.
  OwnRows own_field_rows(FieldId id, int row0, int row1) const {
    return backend_->own_field_rows(id, row0, row1);
  }
  /// The processes a step runs with these parameters, in order.
  std::vector<Process> sequence() const;
  /// The passes a step runs them in (process.hpp step_passes, with numerics.fused_sweeps).
  const std::vector<std::vector<Process>>& passes() const { return passes_; }
  /// Switches numerics.fused_sweeps for the next steps (erodem bench times both ways in one
  /// run); the results do not change.
  void set_fused_sweeps(bool on);
  /// Fraction of the configured run done, in [0, 1].
  double progress() const;
  /// Inputs of the next step (rain rate, inflow volumes) for a step of `dt` seconds.
  StepInputs inputs_for(double dt) const;
  /// snow.air_temperature T_ref at time t (s): its series' value there, or the constant
  /// (degrees C).
  double air_temperature_at(double t) const;
  /// The (col, row) of a DEM cell index, formatted for messages.
  std::string cell_name(std::int64_t cell) const;

 private:
  struct InflowCells {
    std::vector<std::int64_t> cells;  ///< DEM cells the inflow enters, equal shares
    std::size_t spec = 0;             ///< index into params.inflow
  };
  void resolve_inflows();
  /// The active cells beside a cell held at the level (coast_cells_), and their beds (m).
  void find_coast_cells(std::vector<double>& coast_bed);
  /// The statistics of the current state (taken again when state_changed() was called).
  const FieldStats& current_stats() const;
  /// The largest face depth a fixed-level cell presents to an active cell beside it, less
  /// the active cell's own depth: max(0, sea_level - bed) over those active cells (m), from
  /// the bed at coast_cells_ (in that order).
  double coast_depth(const std::vector<double>& coast_bed) const;
  /// An upper bound of the depth per second (m/s) that this step's rain and inflows add to
  /// any one cell, for any step starting now no longer than time.dt_max.
  double source_rise_rate() const;
  /// The largest rise rate one cell takes from the inflows over [t0, t1] (m/s).
  double source_rise_rate_of_inflows(double t0, double t1) const;
  /// What to change when a run goes unstable (time.cfl / time.dt_max, or time.dt).
  std::string stability_advice() const;
  void check_stability(double dt) const;
  /// The diagnostics row of the current state after a step of `dt` seconds.
  Diagnostics diagnostics_now(double dt) const;

  Terrain terrain_;
  /// The smallest cell size and area of the rows the time step looks at: every row, or with
  /// boundary.latitude_cap the rows with an active cell (the capped rows hold no water).
  double dx_min_ = 0.0, area_min_ = 0.0;
  std::vector<std::string> notes_, warnings_;  ///< setup_notes(), setup_warnings()
  /// Sets dx_min_, area_min_, notes_ and warnings_ (simulation.cpp).
  void describe_grid();
  Params params_;
  std::unique_ptr<Backend> backend_;
  std::vector<InflowCells> inflows_;
  /// Every DEM cell that an inflow enters: its area (m^2) and the inflows (indices into
  /// inflows_) that share it.
  struct SourceCell {
    double area = 0.0;
    std::vector<std::size_t> inflows;
  };
  std::vector<SourceCell> source_cells_;
  double rain_area_ = 0.0;        ///< sum(rain_factor * area) over active cells (m^2)
  double active_area_ = 0.0;      ///< sum(area) over active cells (m^2)
  double rain_factor_max_ = 0.0;  ///< largest rain_factor over active cells (1)
  /// rain.grids: each band's rate (m/s) times the rain factor on the DEM cells in time, its
  /// volume rate sum(rate area) over the active cells (m^3/s) and its largest rate (m/s).
  BandSeries rain_grid_;
  std::vector<double> rain_band_volume_, rain_band_max_;
  /// Gives the backend the gridded rain of time t (s) when it changed; returns its volume rate
  /// (m^3/s).
  double set_rain_grid(double t);
  /// snow.temperature_grids: the air temperature at each cell (degrees C) in time.
  BandSeries temperature_grid_;
  /// Active DEM cells beside a fixed-level cell (an edge ghost or a sea nodata cell).
  std::vector<std::int64_t> coast_cells_;
  double time_ = 0.0;
  long steps_ = 0;
  Ledger ledger_;
  // The statistics after the last step, and coast_depth() of the bed then; taken again by
  // current_stats() when stale_ (the state was changed from outside).
  mutable FieldStats stats_;
  mutable double coast_depth_ = 0.0;
  mutable bool stale_ = false;
  Diagnostics diag_;
  // The probes (set_probes) and their samples at the end of the latest step, current until
  // the state changes from outside.
  std::vector<std::int64_t> probe_cells_;
  std::vector<FieldId> probe_fields_;
  std::vector<double> probes_;
  bool probes_current_ = false;
  SectionLayout sections_;
  std::vector<SectionState> section_state_;
  bool sections_measured_ = false;
  /// Terrain classes: the parameter fields their tables write must be written again from the
  /// classes held before the next step (after restore(), which sets terrain_class only).
  std::vector<std::vector<Process>> passes_;  // step_passes of params_, taken when they change
  bool class_fields_stale_ = false;           // a step has set the peaks
  /// Sums a step's face values into section_state_.
  void measure_sections(const StepResult& result, double dt);
};

}  // namespace erodem
