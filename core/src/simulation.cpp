#include "erodem/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "erodem/error.hpp"

namespace erodem {

const std::array<DiagnosticsSeries, 16>& diagnostics_series() {
  static const std::array<DiagnosticsSeries, 16> table{{
      {"time", &Diagnostics::time, "s", "time since the start of the run, at the end of the step"},
      {"dt", &Diagnostics::dt, "s", "time step"},
      {"water_volume", &Diagnostics::water_volume, "m3", "water volume on the grid"},
      {"material_volume", &Diagnostics::material_volume, "m3",
       "bed plus suspended sediment volume"},
      {"rain_volume", &Diagnostics::rain_volume, "m3", "cumulative rain volume"},
      {"inflow_volume", &Diagnostics::inflow_volume, "m3", "cumulative inflow volume"},
      {"boundary_outflow_volume", &Diagnostics::boundary_outflow_volume, "m3",
       "cumulative net outflow through the boundary"},
      {"evaporated_volume", &Diagnostics::evaporated_volume, "m3", "cumulative evaporated volume"},
      {"closure_error", &Diagnostics::closure_error, "m3", "water ledger closure error"},
      {"max_depth", &Diagnostics::max_depth, "m", "largest water depth"},
      {"max_speed", &Diagnostics::max_speed, "m s-1", "largest flow speed"},
      {"eroded_volume", &Diagnostics::eroded_volume, "m3",
       "cumulative bed volume taken into suspension"},
      {"deposited_volume", &Diagnostics::deposited_volume, "m3",
       "cumulative sediment volume laid down on the bed"},
      {"material_closure_error", &Diagnostics::material_closure_error, "m3",
       "material ledger closure error"},
      {"relative_closure_error", &Diagnostics::relative_closure_error, "1",
       "water ledger closure error relative to the water moved"},
      {"relative_material_closure_error", &Diagnostics::relative_material_closure_error, "1",
       "material ledger closure error relative to the material moved"},
  }};
  return table;
}

const char* process_name(Process p) {
  switch (p) {
    case Process::boundary:
      return "boundary";
    case Process::sources:
      return "sources";
    case Process::flow:
      return "flow";
    case Process::water:
      return "water";
    case Process::erosion:
      return "erosion";
    case Process::transport:
      return "transport";
    case Process::thermal:
      return "thermal";
    case Process::evaporation:
      return "evaporation";
  }
  return "?";
}

double series_value(const Series& s, double t) {
  if (s.empty()) return 0.0;
  if (t <= s.front().t) return s.front().value;
  if (t >= s.back().t) return s.back().value;
  const auto hi = std::upper_bound(s.begin(), s.end(), t,
                                   [](double v, const SeriesPoint& p) { return v < p.t; });
  const auto lo = hi - 1;
  const double w = (t - lo->t) / (hi->t - lo->t);
  return lo->value + w * (hi->value - lo->value);
}

const std::vector<FieldId>& state_fields() {
  static const std::vector<FieldId> ids{
      FieldId::bed,        FieldId::initial_bed, FieldId::water_depth, FieldId::sediment,
      FieldId::velocity_x, FieldId::velocity_y,  FieldId::flux_left,   FieldId::flux_right,
      FieldId::flux_top,   FieldId::flux_bottom, FieldId::wetness,     FieldId::bed_residual};
  return ids;
}

RestartPoint Simulation::restart_point() const {
  RestartPoint p;
  p.time = time_;
  p.steps = steps_;
  p.ledger = ledger_;
  for (FieldId id : state_fields()) p.fields.push_back(backend_->field(id));
  return p;
}

void Simulation::restore(const RestartPoint& point) {
  const auto& ids = state_fields();
  if (point.fields.size() != ids.size())
    throw Error(ExitCode::data, fmt::format("restart state: {} fields, expected {}",
                                            point.fields.size(), ids.size()));
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (point.fields[k].size() != terrain_.grid.cells())
      throw Error(ExitCode::data,
                  fmt::format("restart state: field '{}' has {} values for a grid of {} x {}",
                              field_info(ids[k]).name, point.fields[k].size(), terrain_.grid.nx,
                              terrain_.grid.ny));
    backend_->set_field(ids[k], point.fields[k]);
  }
  time_ = point.time;
  steps_ = point.steps;
  ledger_ = point.ledger;
  stats_ = backend_->stats();
  diag_ = diagnostics_now(0.0);
}

Diagnostics Simulation::diagnostics_now(double dt) const {
  return Diagnostics{time_,
                     dt,
                     stats_.water_volume,
                     stats_.material_volume,
                     ledger_.rain,
                     ledger_.inflow,
                     ledger_.boundary_out,
                     ledger_.evaporated,
                     ledger_.closure_error(),
                     stats_.max_depth,
                     stats_.max_speed,
                     ledger_.eroded,
                     ledger_.deposited,
                     ledger_.material_closure_error(),
                     ledger_.relative_closure_error(),
                     ledger_.relative_material_closure_error()};
}

Simulation::Simulation(Terrain terrain, Params params, std::unique_ptr<Backend> backend)
    : terrain_(std::move(terrain)), params_(std::move(params)), backend_(std::move(backend)) {
  if (!backend_) throw Error(ExitCode::internal, "simulation: no backend");
  terrain_.grid.validate();
  const auto& g = terrain_.grid;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * g.nx + c;
      if (terrain_.active(i))
        rain_area_ += g.area[r] * (terrain_.rain_factor.empty() ? 1.0 : terrain_.rain_factor[i]);
    }
  resolve_inflows();
  stats_ = backend_->stats();
  if (stats_.bad_cell >= 0)
    throw Error(ExitCode::data, "initial state: cell " + cell_name(stats_.bad_cell) +
                                    " has a NaN, infinite or negative value");
  ledger_.water_initial = ledger_.water = stats_.water_volume;
  ledger_.material_initial = ledger_.material = stats_.material_volume;
  diag_.water_volume = stats_.water_volume;
  diag_.material_volume = stats_.material_volume;
  diag_.max_depth = stats_.max_depth;
  diag_.max_speed = stats_.max_speed;
}

void Simulation::resolve_inflows() {
  const auto& g = terrain_.grid;
  for (std::size_t k = 0; k < params_.inflow.size(); ++k) {
    const auto& spec = params_.inflow[k];
    const std::string key = fmt::format("inflow[{}]", k);
    InflowCells ic;
    ic.spec = k;
    std::set<std::int64_t> seen;
    auto add_point = [&](double x, double y) {
      int col = 0, row = 0;
      if (!g.locate(x, y, col, row)) return;
      const std::int64_t cell = static_cast<std::int64_t>(row) * g.nx + col;
      if (terrain_.active(static_cast<std::size_t>(cell)) && seen.insert(cell).second)
        ic.cells.push_back(cell);
    };
    if (spec.vertices.size() == 1) {
      add_point(spec.vertices[0][0], spec.vertices[0][1]);
    } else {
      // Sample each segment at a quarter of the smallest cell size.
      const double step = 0.25 * g.dx_min();
      for (std::size_t v = 0; v + 1 < spec.vertices.size(); ++v) {
        const auto& a = spec.vertices[v];
        const auto& b = spec.vertices[v + 1];
        const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
        const long n = std::max(1L, static_cast<long>(std::ceil(len / step)));
        for (long s = 0; s <= n; ++s) {
          const double w = static_cast<double>(s) / n;
          add_point(a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]));
        }
      }
    }
    if (ic.cells.empty())
      throw config_error(key,
                         "no active DEM cell under its point/line (check the coordinates "
                         "are in the DEM's CRS and inside the grid)");
    inflows_.push_back(std::move(ic));
  }
}

std::vector<Process> Simulation::sequence() const {
  std::vector<Process> seq{Process::boundary, Process::sources, Process::flow, Process::water};
  if (params_.erosion.enabled) {
    seq.push_back(Process::erosion);
    seq.push_back(Process::transport);
  }
  if (params_.thermal.enabled) seq.push_back(Process::thermal);
  seq.push_back(Process::evaporation);
  return seq;
}

double Simulation::next_dt() const {
  const auto& t = params_.time;
  double dt = t.dt;
  if (t.adaptive) {
    const double g = params_.flow.gravity;
    const double dx_min = terrain_.grid.dx_min();
    dt = t.dt_max;
    // The fastest signal: gravity waves (sqrt(g d)) carried by the flow (|u|). Local
    // inertial drops advection, so sqrt(g d) alone keeps it stable (Bates et al. 2010), but
    // a thin film on a steep cell is supercritical (1 mm on a slope of 1: u = 0.33 m/s,
    // sqrt(g d) = 0.10 m/s): where its kinematic wave crosses more than a cell per step the
    // outflow limit cuts the discharge and the run-off lags (on a 100 m plane of slope 1
    // with 1 m cells and dt = 5 s the outlet reached half its equilibrium discharge at 213 s,
    // not 112 s; tests/test_runoff.cpp).
    const double signal = stats_.max_speed + std::sqrt(g * stats_.max_depth);
    if (signal > 0) dt = std::min(dt, t.cfl * dx_min / signal);
    if (params_.flow.scheme == FlowScheme::pipes) {
      // Stability of the pipe oscillator: dt < sqrt(l * area / (2 A g)).
      double area_min = HUGE_VAL;
      for (double a : terrain_.grid.area) area_min = std::min(area_min, a);
      const double l = params_.flow.pipe_length > 0 ? params_.flow.pipe_length : dx_min;
      dt = std::min(dt, t.cfl * std::sqrt(l * area_min / (2.0 * params_.flow.pipe_area * g)));
    }
  }
  if (t.duration > 0) {
    // End exactly at the duration without a sliver of a last step: a tiny dt lets the
    // outflow limit pass fluxes up to depth * area / dt, which shows as spurious speeds.
    const double remaining = t.duration - time_;
    if (remaining <= dt)
      dt = remaining;
    else if (remaining < 2.0 * dt)
      dt = 0.5 * remaining;
  }
  return dt;
}

bool Simulation::finished() const {
  const auto& t = params_.time;
  if (t.duration > 0) return time_ >= t.duration * (1.0 - 1e-12);
  return steps_ >= t.steps;
}

double Simulation::progress() const {
  const auto& t = params_.time;
  if (t.duration > 0) return std::clamp(time_ / t.duration, 0.0, 1.0);
  return t.steps > 0 ? std::clamp(static_cast<double>(steps_) / t.steps, 0.0, 1.0) : 1.0;
}

StepInputs Simulation::inputs_for(double dt) const {
  StepInputs in;
  in.t = time_;
  in.dt = dt;
  const double t_mid = time_ + 0.5 * dt;
  in.rain_rate =
      params_.rain.series.empty() ? params_.rain.rate : series_value(params_.rain.series, t_mid);
  for (const auto& ic : inflows_) {
    const double q = series_value(params_.inflow[ic.spec].hydrograph, t_mid);
    const double share = q * dt / static_cast<double>(ic.cells.size());
    for (auto cell : ic.cells) in.points.push_back({cell, share});
  }
  return in;
}

std::string Simulation::cell_name(std::int64_t cell) const {
  const auto nx = terrain_.grid.nx;
  const int col = static_cast<int>(cell % nx), row = static_cast<int>(cell / nx);
  const auto xy = terrain_.grid.cell_center(col, row);
  return fmt::format("(col {}, row {}; x {:.6g}, y {:.6g})", col, row, xy[0], xy[1]);
}

void Simulation::check_stability(double dt) const {
  if (stats_.bad_cell >= 0) {
    const auto c = static_cast<std::size_t>(stats_.bad_cell);
    const auto d = backend_->field(FieldId::water_depth)[c];
    const auto b = backend_->field(FieldId::bed)[c];
    throw Error(ExitCode::unstable,
                fmt::format("unstable at step {} (t = {:.6g} s): cell {} has depth {:.6g} m, "
                            "bed {:.6g} m; lower time.dt or set time.adaptive = true",
                            steps_, time_, cell_name(stats_.bad_cell), d, b));
  }
  if (params_.flow.scheme == FlowScheme::local_inertial && stats_.max_depth > 0) {
    const double courant =
        dt * std::sqrt(params_.flow.gravity * stats_.max_depth) / terrain_.grid.dx_min();
    if (courant > 1.0)
      throw Error(
          ExitCode::unstable,
          fmt::format("CFL violated at step {} (t = {:.6g} s): cell {} with depth "
                      "{:.6g} m has dt sqrt(g d) / dx = {:.4g} > 1; lower time.dt or "
                      "set time.adaptive = true",
                      steps_, time_, cell_name(stats_.max_depth_cell), stats_.max_depth, courant));
  }
}

void Simulation::step() {
  const double dt = next_dt();
  if (!(dt > 0)) throw Error(ExitCode::internal, "time step is not positive");
  const StepInputs in = inputs_for(dt);
  StepTally tally;
  for (Process p : sequence()) backend_->run(p, in, tally);
  time_ += dt;
  ++steps_;
  stats_ = backend_->stats();

  double added = 0.0;
  for (const auto& p : in.points) added += p.volume;
  ledger_.rain += in.rain_rate * dt * rain_area_;
  ledger_.inflow += added;
  ledger_.boundary_out += tally.boundary_water_out;
  ledger_.evaporated += tally.evaporated;
  ledger_.clipped += tally.clipped;
  ledger_.sediment_out += tally.sediment_out;
  ledger_.transport_change += tally.transport_change;
  ledger_.water_exchanged += tally.water_exchanged;
  ledger_.eroded += tally.eroded;
  ledger_.deposited += tally.deposited;
  ledger_.sediment_exchanged += tally.sediment_exchanged;
  ledger_.thermal_moved += tally.thermal_moved;
  ledger_.water = stats_.water_volume;
  ledger_.material = stats_.material_volume;

  diag_ = diagnostics_now(dt);
  // Check after the books are updated, so a caller catching the error sees this step.
  check_stability(dt);
}

void Simulation::step(long n) {
  for (long k = 0; k < n; ++k) step();
}

void Simulation::run(const std::function<void(const Simulation&)>& on_step) {
  while (!finished()) {
    step();
    if (on_step) on_step(*this);
  }
}

}  // namespace erodem
