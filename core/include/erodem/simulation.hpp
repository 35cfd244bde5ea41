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
#include "erodem/grid.hpp"
#include "erodem/ledger.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// Value of a piecewise-linear series at time t (s); held constant beyond its ends.
double series_value(const Series& s, double t);

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

/// The fields a backend keeps from one step to the next (everything else is derived from
/// the terrain and the parameters, or recomputed within a step).
const std::vector<FieldId>& state_fields();

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

  /// The time step the next step will take (s).
  double next_dt() const;

  double time() const { return time_; }
  long steps_done() const { return steps_; }
  const Ledger& ledger() const { return ledger_; }
  const Diagnostics& diagnostics() const { return diag_; }
  const FieldStats& last_stats() const { return stats_; }
  const Params& params() const { return params_; }
  const Terrain& terrain() const { return terrain_; }
  const Grid& grid() const { return terrain_.grid; }
  Backend& backend() { return *backend_; }
  const Backend& backend() const { return *backend_; }
  /// A field, row-major (ny, nx), in SI units.
  std::vector<double> field(FieldId id) const { return backend_->field(id); }
  /// The processes a step runs with these parameters, in order.
  std::vector<Process> sequence() const;
  /// Fraction of the configured run done, in [0, 1].
  double progress() const;
  /// Inputs of the next step (rain rate, inflow volumes) for a step of `dt` seconds.
  StepInputs inputs_for(double dt) const;
  /// The (col, row) of a DEM cell index, formatted for messages.
  std::string cell_name(std::int64_t cell) const;

 private:
  struct InflowCells {
    std::vector<std::int64_t> cells;  ///< DEM cells the inflow enters, equal shares
    std::size_t spec = 0;             ///< index into params.inflow
  };
  void resolve_inflows();
  void check_stability(double dt) const;
  /// The diagnostics row of the current state after a step of `dt` seconds.
  Diagnostics diagnostics_now(double dt) const;

  Terrain terrain_;
  Params params_;
  std::unique_ptr<Backend> backend_;
  std::vector<InflowCells> inflows_;
  double rain_area_ = 0.0;  ///< sum(rain_factor * area) over active cells (m^2)
  double time_ = 0.0;
  long steps_ = 0;
  Ledger ledger_;
  FieldStats stats_;
  Diagnostics diag_;
};

}  // namespace erodem
