#include "erodem/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>

#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/parallel.hpp"
#include "erodem/process.hpp"
#include "erodem/terrain_rows.hpp"

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

double series_max(const Series& s, double t0, double t1) {
  double m = std::max(series_value(s, t0), series_value(s, t1));
  for (const auto& p : s)
    if (p.t > t0 && p.t < t1) m = std::max(m, p.value);
  return m;
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
  for (std::size_t k = 0; k < ids.size(); ++k)
    if (point.fields[k].size() != terrain_.grid.cells())
      throw Error(ExitCode::data,
                  fmt::format("restart state: field '{}' has {} values for a grid of {} x {}",
                              field_info(ids[k]).name, point.fields[k].size(), terrain_.grid.nx,
                              terrain_.grid.ny));
  const auto nx = static_cast<std::ptrdiff_t>(terrain_.grid.nx);
  restore(point, [&](FieldId id, int row0, int row1) {
    const std::size_t k =
        static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin());
    const auto& f = point.fields.at(k);
    return std::vector<double>(f.begin() + row0 * nx, f.begin() + row1 * nx);
  });
}

void Simulation::restore(const RestartPoint& point, const StateRows& rows) {
  // each state field in turn (the bed before its residual, as set_field_rows asks), a strip at
  // a time, of the rows the terrain holds (the backend's band and halo lie within them); the
  // strips end on multiples of kRestoreStrip, the result files' chunk height, so that no chunk
  // is read (and decompressed) for two strips
  const int first = terrain_.row0, last = terrain_.end_row();
  const auto nx = static_cast<std::size_t>(terrain_.grid.nx);
  for (FieldId id : state_fields())
    for (int r0 = first, r1 = 0; r0 < last; r0 = r1) {
      r1 = std::min(last, (r0 / kRestoreStrip + 1) * kRestoreStrip);
      const std::vector<double> v = rows(id, r0, r1);
      if (v.size() != static_cast<std::size_t>(r1 - r0) * nx)
        throw Error(ExitCode::internal,
                    fmt::format("restart state: {} values of field '{}' for rows [{}, {})",
                                v.size(), field_info(id).name, r0, r1));
      backend_->set_field_rows(id, r0, r1, v);
    }
  time_ = point.time;
  steps_ = point.steps;
  ledger_ = point.ledger;
  class_fields_stale_ = true;
  state_changed();
  diag_ = diagnostics_now(0.0);
}

const FieldStats& Simulation::current_stats() const {
  if (stale_) {
    stats_ = backend_->stats();
    if (!coast_cells_.empty())
      coast_depth_ = coast_depth(backend_->sample(coast_cells_, FieldId::bed));
    stale_ = false;
  }
  return stats_;
}

Diagnostics Simulation::diagnostics_now(double dt) const {
  const FieldStats& stats = current_stats();
  return Diagnostics{time_,
                     dt,
                     stats.water_volume,
                     stats.material_volume,
                     ledger_.rain,
                     ledger_.inflow,
                     ledger_.boundary_out,
                     ledger_.evaporated,
                     ledger_.closure_error(),
                     stats.max_depth,
                     stats.max_speed,
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
  // every field a sweep of the step reads is provided before it (process.hpp)
  check_sweeps(step_sweeps(params_));
  passes_ = step_passes(params_, params_.numerics.fused_sweeps);
  describe_grid();
  const auto& g = terrain_.grid;
  // The sums over the active cells (the rain factor's area, each rain band's volume) add the
  // terms of every row, or on a rank holding its band's rows (Terrain::banded) those of its own
  // rows to the running sums carried through the ranks in row order (the bits of one process:
  // parallel::sums_in_rank_order); the maxima the largest over the ranks.
  const parallel::Band own = own_rows(terrain_);
  const auto sums = [&](std::size_t n, const std::function<void(std::vector<double>&)>& add) {
    if (terrain_.banded) return parallel::sums_in_rank_order(n, add);
    std::vector<double> all(n, 0.0);  // every rank adds every row
    add(all);
    return all;
  };
  const auto largest = [&](double mine) {
    return terrain_.banded ? parallel::max_over_ranks(mine) : mine;
  };
  // a row-major loop over the active cells of rows [r0, r1): f(cell, row)
  const auto each_active = [&](int r0, int r1, const auto& f) {
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < g.nx; ++c) {
        const auto i = static_cast<std::size_t>(r) * g.nx + c;
        if (terrain_.active(i)) f(i, r);
      }
  };
  const auto factor = [this](std::size_t i) {
    return terrain_.rain_factor.empty() ? 1.0 : terrain_.rain_factor[terrain_.held(i)];
  };
  const std::vector<double> areas = sums(2, [&](std::vector<double>& area) {
    each_active(own.row0, own.row1, [&](std::size_t i, int r) {
      area[0] += g.area[r] * factor(i);
      area[1] += g.area[r];
      rain_factor_max_ = std::max(rain_factor_max_, factor(i));
    });
  });
  rain_area_ = areas[0];
  active_area_ = areas[1];
  rain_factor_max_ = largest(rain_factor_max_);
  if (!terrain_.rain_grids.empty()) {
    const double scale = params_.rain.grid_scale;
    std::vector<std::vector<double>> rates;  // on the rows the terrain holds, 0 off the active
    for (const auto& band : terrain_.rain_grids) {
      if (band.size() != terrain_.held_cells())
        throw Error(ExitCode::data, "rain.grids: a band's size differs from the grid's");
      std::vector<double> rate(band.size(), 0.0);
      each_active(terrain_.row0, terrain_.end_row(), [&](std::size_t i, int) {
        rate[terrain_.held(i)] = band[terrain_.held(i)] * scale * factor(i);
      });
      double top = 0.0;
      each_active(own.row0, own.row1,
                  [&](std::size_t i, int) { top = std::max(top, rate[terrain_.held(i)]); });
      rates.push_back(std::move(rate));
      rain_band_max_.push_back(largest(top));
    }
    rain_band_volume_ = sums(rates.size(), [&](std::vector<double>& volume) {
      for (std::size_t k = 0; k < rates.size(); ++k)
        each_active(own.row0, own.row1, [&](std::size_t i, int r) {
          volume[k] += rates[k][terrain_.held(i)] * g.area[r];
        });
    });
    const auto& rain = params_.rain;
    rain_grid_ =
        BandSeries(std::move(rates),
                   {rain.grid_start, rain.grid_interval,
                    terrain_.rain_grid_times.empty() ? rain.grid_times : terrain_.rain_grid_times},
                   "rain.grid_times");
  }
  if (params_.snow.enabled && !params_.snow.temperature_grids.empty()) {
    const auto& sn = params_.snow;
    if (terrain_.temperature_grids.empty())
      throw Error(ExitCode::data, "snow.temperature_grids: " + sn.temperature_grids +
                                      ": the terrain holds none of its bands");
    // on the rows the terrain holds, 0 off the active cells (nodata there)
    std::vector<std::vector<double>> bands;
    for (const auto& band : terrain_.temperature_grids) {
      if (band.size() != terrain_.held_cells())
        throw Error(ExitCode::data,
                    "snow.temperature_grids: a band's size differs from the grid's");
      bands.emplace_back(band.size(), 0.0);
      each_active(terrain_.row0, terrain_.end_row(), [&](std::size_t i, int) {
        bands.back()[terrain_.held(i)] = band[terrain_.held(i)];
      });
    }
    temperature_grid_ =
        BandSeries(std::move(bands),
                   {sn.temperature_grid_start, sn.temperature_grid_interval,
                    terrain_.temperature_grid_times.empty() ? sn.temperature_grid_times
                                                            : terrain_.temperature_grid_times},
                   "snow.temperature_grid_times");
  }
  resolve_inflows();
  sections_ = layout_sections(terrain_, params_);
  section_state_.assign(sections_.names.size(), SectionState{});
  if (!sections_.faces.empty()) backend_->set_faces(sections_.faces);
  std::vector<double> coast_bed;  // the coast cells' beds
  find_coast_cells(coast_bed);
  // the initial values of the fields the processes own (process.hpp ProcessInfo::initial)
  // (a strip of rows at a time: a whole field in double would be 8 B per cell beside the
  // state, the setup's peak)
  // (a terrain of a band's rows: those of them whose neighbours it holds too, which hold the
  // backend's rows: io::load_terrain)
  const int first_row = terrain_.row0 == 0 ? 0 : terrain_.row0 + 1,
            end_row = terrain_.end_row() == g.ny ? g.ny : terrain_.end_row() - 1;
  for (const Process p : step_sequence(params_))
    if (const auto initial = process_info(p).initial)
      for (const InitialField& f : initial(terrain_, params_)) {
        constexpr int kStrip = 256;  // rows
        std::vector<double> values;
        for (int row0 = first_row; row0 < end_row; row0 += kStrip) {
          const int row1 = std::min(end_row, row0 + kStrip);
          const std::size_t first = static_cast<std::size_t>(row0) * g.nx;
          values.resize(static_cast<std::size_t>(row1 - row0) * g.nx);
          for (std::size_t i = 0; i < values.size(); ++i) values[i] = f.value(first + i);
          backend_->set_field_rows(f.id, row0, row1, values);
        }
      }
  // the terrain classes of the initial state, so that the first snapshot shows them (the
  // first step classifies the same state again: the same classes)
  if (params_.terrain_classes.enabled) {
    backend_->begin_step(StepInputs{});
    backend_->run(Process::terrain_class);
    backend_->end_step();
  }
  stats_ = backend_->stats();
  coast_depth_ = coast_depth(coast_bed);
  if (stats_.bad_cell >= 0)
    throw Error(ExitCode::data, "initial state: cell " + cell_name(stats_.bad_cell) +
                                    " has a NaN, infinite or negative value");
  ledger_.water_initial = ledger_.water = stats_.water_volume;
  ledger_.material_initial = ledger_.material = stats_.material_volume;
  diag_.water_volume = stats_.water_volume;
  diag_.material_volume = stats_.material_volume;
  diag_.max_depth = stats_.max_depth;
  diag_.max_speed = stats_.max_speed;
  // the backend holds the state, the rain and temperature series their bands: from here on
  // the terrain is its grid and mask
  terrain_.release_cell_inputs();
}

void Simulation::describe_grid() {
  const Grid& g = terrain_.grid;
  dx_min_ = g.dx_min();
  area_min_ = HUGE_VAL;
  for (double a : g.area) area_min_ = std::min(area_min_, a);
  // the rows with an active cell: the narrowest and the widest of them
  const std::vector<std::uint8_t> rows = rows_with_active(terrain_);
  const auto any = [&rows](int r) { return rows[static_cast<std::size_t>(r)] != 0; };
  int narrow = -1, wide = -1;
  for (int r = 0; r < g.ny; ++r) {
    if (!any(r)) continue;
    if (narrow < 0 || g.dx[r] < g.dx[narrow]) narrow = r;
    if (wide < 0 || g.dx[r] > g.dx[wide]) wide = r;
  }
  if (params_.boundary.latitude_cap && narrow >= 0) {
    dx_min_ = HUGE_VAL;
    area_min_ = HUGE_VAL;
    for (int r = 0; r < g.ny; ++r) {
      if (!any(r)) continue;
      dx_min_ = std::min({dx_min_, g.dx[r], g.dy[r]});
      area_min_ = std::min(area_min_, g.area[r]);
    }
  }
  notes_ = terrain_.notes;
  if (periodic_x(terrain_, params_)) {
    const double span = g.nx * std::fabs(g.georef.transform[1]);
    const char* why = !params_.boundary.periodic_x && spans_360(g)
                          ? "the grid spans 360 degrees of longitude; boundary.periodic_x = false "
                            "keeps them apart"
                      : spans_360(g)
                          ? "boundary.periodic_x = true"
                          : "asked for by boundary.periodic_x or boundary.east and .west "
                            "= \"periodic\"";
    notes_.push_back(fmt::format(
        "the east and west edges are joined (periodic): water leaving east enters west ({}){}", why,
        spans_360(g) ? std::string()
        : g.georef.is_geographic
            ? fmt::format("; the grid spans {:.6g} degrees of longitude, not 360", span)
            : std::string("; the grid is not a lat/lon grid spanning 360 degrees")));
  }
  // The time step's limits scale with the narrowest cells: on a lat/lon grid those of the
  // rows nearest a pole (dx = R cos(latitude) dlon).
  if (g.georef.is_geographic && narrow >= 0 && g.dx[narrow] < 0.5 * g.dx[wide]) {
    const double gravity = params_.flow.gravity, cfl = params_.time.cfl;
    const double dt_narrow = cfl * g.dx[narrow] / std::sqrt(gravity * 1.0);
    const double dt_wide = cfl * std::min(g.dx[wide], g.dy[wide]) / std::sqrt(gravity * 1.0);
    warnings_.push_back(fmt::format(
        "near a pole the cells narrow: row {} (latitude {:.4g} degrees) has dx = {:.4g} m, "
        "{:.3g} times narrower than row {} (latitude {:.4g} degrees, dx = {:.4g} m), and the "
        "time step limit shrinks with it (for 1 m of water, CFL {:.3g}: {:.4g} s there against "
        "{:.4g} s); {} boundary.latitude_cap (degrees{}) to make the rows poleward of it walls",
        narrow, g.cell_center(0, narrow)[1], g.dx[narrow], g.dx[wide] / g.dx[narrow], wide,
        g.cell_center(0, wide)[1], g.dx[wide], cfl, dt_narrow, dt_wide,
        params_.boundary.latitude_cap ? "lower" : "set",
        params_.boundary.latitude_cap ? fmt::format(", now {:.6g}", *params_.boundary.latitude_cap)
                                      : std::string(", e.g. 85")));
  }
}

void Simulation::resolve_inflows() {
  const auto& g = terrain_.grid;
  for (std::size_t k = 0; k < params_.inflow.size(); ++k) {
    const auto& spec = params_.inflow[k];
    const std::string key = fmt::format("inflow[{}]", k);
    InflowCells ic;
    ic.spec = k;
    // the cells under its points in order, then those of them active, each once
    std::vector<std::int64_t> under;
    auto add_point = [&](double x, double y) {
      int col = 0, row = 0;
      if (!g.locate(x, y, col, row)) return;
      const std::int64_t cell = static_cast<std::int64_t>(row) * g.nx + col;
      if (under.empty() || under.back() != cell) under.push_back(cell);
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
    const std::vector<std::uint8_t> on = cells_active(terrain_, under);
    std::set<std::int64_t> seen;
    for (std::size_t j = 0; j < under.size(); ++j)
      if (on[j] && seen.insert(under[j]).second) ic.cells.push_back(under[j]);
    if (ic.cells.empty())
      throw config_error(key,
                         "no active DEM cell under its point/line (check the coordinates "
                         "are in the DEM's CRS and inside the grid)");
    inflows_.push_back(std::move(ic));
  }
  std::map<std::int64_t, std::size_t> slot;  // cell -> index into source_cells_
  for (std::size_t k = 0; k < inflows_.size(); ++k)
    for (auto cell : inflows_[k].cells) {
      const auto [it, added] = slot.emplace(cell, source_cells_.size());
      if (added) source_cells_.push_back({g.area[static_cast<std::size_t>(cell / g.nx)], {}});
      source_cells_[it->second].inflows.push_back(k);
    }
}

void Simulation::find_coast_cells(std::vector<double>& coast_bed) {
  const auto& g = terrain_.grid;
  constexpr BoundaryKind fixed_level = BoundaryKind::fixed_level;
  // Whether active cell (c, r)'s neighbour (c + dc, r + dr) is a fixed-level cell: the ghost of
  // an edge held at the level there, or a cell held at it (boundary_codes.hpp, as
  // initial_state.cpp gives the kinds).
  auto fixed = [&](int c, int r, int dc, int dr, Side side) {
    const int nc = c + dc, nr = r + dr;
    if (nc < 0 || nr < 0 || nc >= g.nx || nr >= g.ny)
      return ghost_condition(terrain_, params_, c, r, side) == fixed_level;
    const auto n = static_cast<std::size_t>(nr) * g.nx + nc;
    return !terrain_.active(n) && held_at_level(terrain_, params_, n);
  };
  // on the rows this process owns (a banded terrain holds the rows beside them too), each
  // with its bed (in double, as read); the ranks' lists in rank order are the grid's, in
  // row-major order
  const parallel::Band own = own_rows(terrain_);
  for (int r = own.row0; r < own.row1; ++r)
    for (int c = 0; c < g.nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * g.nx + c;
      if (terrain_.active(i) &&
          (fixed(c, r, -1, 0, Side::west) || fixed(c, r, 1, 0, Side::east) ||
           fixed(c, r, 0, -1, Side::north) || fixed(c, r, 0, 1, Side::south))) {
        coast_cells_.push_back(static_cast<std::int64_t>(i));
        coast_bed.push_back(terrain_.bed[terrain_.held(i)]);
      }
    }
  if (terrain_.banded) {
    coast_cells_ = parallel::allgather(coast_cells_);
    coast_bed = parallel::allgather(coast_bed);
  }
}

double Simulation::coast_depth(const std::vector<double>& coast_bed) const {
  // A fixed-level cell g beside active cell a holds its surface at the level over a bed no
  // higher than a's (boundary.h, initial_state.cpp), so the flow kernel's face depth
  // h_f = max(eta_g, eta_a) - max(b_g, b_a) = max(level - b_a, d_a); the highest level the
  // stage hydrograph reaches bounds it over the run.
  double h = 0.0;
  const double level = boundary_level_range(params_).second;
  for (const double b : coast_bed) h = std::max(h, level - b);
  return h;
}

void Simulation::set_probes(const std::vector<std::int64_t>& cells,
                            const std::vector<FieldId>& fields) {
  backend_->set_probes(cells, fields);
  probe_cells_ = cells;
  probe_fields_ = fields;
  probes_.clear();
  probes_current_ = false;
}

double Simulation::set_rain_grid(double t) {
  const auto [k, w] = rain_grid_.at(t);
  const double volume =
      w > 0 ? (1 - w) * rain_band_volume_[k] + w * rain_band_volume_[k + 1] : rain_band_volume_[k];
  if (auto rate = rain_grid_.values_if_changed(t))
    backend_->set_field_rows(FieldId::rain_factor, terrain_.row0, terrain_.end_row(), *rate);
  return volume;
}

double Simulation::source_rise_rate() const {
  // Inputs are taken at the step's midpoint t + dt / 2 (inputs_for), within [t, t + dt_max / 2].
  const double t0 = time_, t1 = time_ + 0.5 * params_.time.dt_max;
  const auto& rain = params_.rain;
  if (!rain_grid_.empty()) {  // the largest rate of the bands the window touches
    const std::size_t k0 = rain_grid_.at(t0).first;
    const std::size_t k1 = std::min(rain_grid_.at(t1).first + 1, rain_grid_.size() - 1);
    double top = 0.0;
    for (std::size_t k = k0; k <= k1; ++k) top = std::max(top, rain_band_max_[k]);
    return top + source_rise_rate_of_inflows(t0, t1);
  }
  const double rain_rate = rain.series.empty() ? rain.rate : series_max(rain.series, t0, t1);
  return std::max(rain_rate, 0.0) * rain_factor_max_ + source_rise_rate_of_inflows(t0, t1);
}

double Simulation::source_rise_rate_of_inflows(double t0, double t1) const {
  double per_cell_max = 0.0;  // the largest inflow rise rate of one cell (m/s)
  std::vector<double> q(inflows_.size());
  for (std::size_t k = 0; k < inflows_.size(); ++k)
    q[k] = series_max(params_.inflow[inflows_[k].spec].hydrograph, t0, t1) /
           static_cast<double>(inflows_[k].cells.size());
  for (const auto& sc : source_cells_) {
    double sum = 0.0;
    for (auto k : sc.inflows) sum += q[k];
    per_cell_max = std::max(per_cell_max, sum / sc.area);
  }
  return per_cell_max;
}

std::vector<Process> Simulation::sequence() const {
  // The enabled entries of the process table, in its order (process.hpp): the sources run
  // after the flow, so the fluxes of a step come from the depth at its start and the step's
  // rain and inflows enter the continuity update with them (model.md section 2).
  return step_sequence(params_);
}

void Simulation::set_fused_sweeps(bool on) {
  params_.numerics.fused_sweeps = on;
  passes_ = step_passes(params_, on);
}

double Simulation::next_dt() const {
  const auto& t = params_.time;
  double dt = t.dt;
  if (t.adaptive) {
    const double g = params_.flow.gravity;
    const double dx_min = dx_min_;
    const FieldStats& stats = current_stats();
    // The depth the flow kernel sees in this step: the deepest cell's after this step's
    // sources, d_max + s dt (s: source_rise_rate), and at a fixed-level face the sea's depth
    // over the active cell's bed (coast_depth). dt is the largest step whose fastest signal
    // crosses at most alpha dx_min.
    // The shallow-water scheme's condition is the unsplit one, dt max((|u| + c) / dx +
    // (|v| + c) / dy) <= cfl (positivity; Audusse et al. 2004): with |u|, |v| <= the speed
    // and dx, dy >= dx_min, half the reach of the others keeps it.
    const double reach =
        (params_.flow.scheme == FlowScheme::shallow_water ? 0.5 : 1.0) * t.cfl * dx_min;
    const double d = std::max(stats.max_depth, 0.0), s = source_rise_rate();
    dt = t.dt_max;
    if (coast_depth_ > 0) dt = std::min(dt, reach / std::sqrt(g * coast_depth_));
    // The fastest signal is a gravity wave carried by the flow, u + sqrt(g h). Local inertial
    // drops advection, so sqrt(g h) alone keeps it stable (Bates et al. 2010), but a thin
    // film on a steep cell is supercritical (1 mm on a slope of 1: u = 0.33 m/s,
    // sqrt(g h) = 0.10 m/s), and where its kinematic wave crosses more than a cell per step
    // the outflow limit cuts the discharge and the run-off lags (a 100 m plane of slope 1,
    // 1 m cells, dt = 5 s: the outlet reached half its equilibrium discharge at 213 s, not
    // 112 s; tests/test_runoff.cpp). So dt is the root of the increasing, convex
    // f(dt) = dt (u_max + sqrt(g (d_max + s dt))) - alpha dx_min.
    // (local inertial only: the pipes' discharge does not depend on the face depth, so their
    // velocity over it is no speed a signal travels at; their waves move at sqrt(g A dx /
    // (l dy)), bounded below)
    const double u =
        params_.flow.scheme != FlowScheme::pipes ? std::max(stats.max_speed, 0.0) : 0.0;
    if (d > 0 || s > 0 || u > 0) {
      // Newton from the right of the root: both starts have f >= 0, and f is convex and
      // increasing for dt > 0, so the iterates fall monotonically onto the root.
      double x = HUGE_VAL;
      if (d > 0 || u > 0) x = reach / (u + std::sqrt(g * d));
      if (s > 0) x = std::min(x, std::cbrt(reach * reach / (g * s)));
      for (int k = 0; k < 100; ++k) {
        const double c = std::sqrt(g * (d + s * x));
        const double f = x * (u + c) - reach;
        const double slope = u + c + (c > 0 ? x * g * s / (2.0 * c) : 0.0);
        const double next = x - f / slope;
        if (!(next < x)) break;
        x = next;
      }
      dt = std::min(dt, x);
    }
    if (params_.flow.scheme == FlowScheme::pipes) {
      // Stability of the pipe oscillator: dt < sqrt(l * area / (2 A g)).
      const double area_min = area_min_;
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
  in.boundary_level = boundary_level(params_, t_mid);
  if (!rain_grid_.empty()) in.rain_rate = 1.0;  // the rain_factor field holds the rate (m/s)
  in.air_temperature = air_temperature_at(t_mid);
  for (const auto& ic : inflows_) {
    const double q = series_value(params_.inflow[ic.spec].hydrograph, t_mid);
    const double share = q * dt / static_cast<double>(ic.cells.size());
    // the sediment it brings (only where sediment moves: erosion on; schema.cpp checks)
    const double c = params_.erosion.enabled ? params_.inflow[ic.spec].sediment_concentration : 0;
    for (auto cell : ic.cells) in.points.push_back({cell, share, c * share});
  }
  return in;
}

double Simulation::air_temperature_at(double t) const {
  const auto& sn = params_.snow;
  return sn.air_temperature_series.empty() ? sn.air_temperature
                                           : series_value(sn.air_temperature_series, t);
}

std::string Simulation::cell_name(std::int64_t cell) const {
  const auto nx = terrain_.grid.nx;
  const int col = static_cast<int>(cell % nx), row = static_cast<int>(cell / nx);
  const auto xy = terrain_.grid.cell_center(col, row);
  return fmt::format("(col {}, row {}; x {:.6g}, y {:.6g})", col, row, xy[0], xy[1]);
}

std::string Simulation::stability_advice() const {
  return params_.time.adaptive ? "lower time.cfl or time.dt_max"
                               : "lower time.dt or set time.adaptive = true";
}

void Simulation::check_stability(double dt) const {
  const FieldStats& stats = current_stats();
  if (stats.bad_cell >= 0) {
    const std::vector<std::int64_t> cell{stats.bad_cell};
    const double d = backend_->sample(cell, FieldId::water_depth)[0];
    const double b = backend_->sample(cell, FieldId::bed)[0];
    throw Error(ExitCode::unstable,
                fmt::format("unstable at step {} (t = {:.6g} s): cell {} has depth {:.6g} m, "
                            "bed {:.6g} m; {}",
                            steps_, time_, cell_name(stats.bad_cell), d, b, stability_advice()));
  }
  if (params_.flow.scheme != FlowScheme::pipes && stats.max_depth > 0) {
    const double courant = dt * std::sqrt(params_.flow.gravity * stats.max_depth) / dx_min_;
    if (courant > 1.0)
      throw Error(ExitCode::unstable,
                  fmt::format("CFL violated at step {} (t = {:.6g} s): cell {} with depth "
                              "{:.6g} m has dt sqrt(g d) / dx = {:.4g} > 1; {}",
                              steps_, time_, cell_name(stats.max_depth_cell), stats.max_depth,
                              courant, stability_advice()));
  }
}

void Simulation::step() {
  const double dt = next_dt();
  if (!(dt > 0)) throw Error(ExitCode::internal, "time step is not positive");
  StepInputs in = inputs_for(dt);
  // terrain classes: classified on every terrain_classes.interval-th step (the first one
  // included), their tables written again after a restart; otherwise the pass is skipped
  const bool classify = steps_ % params_.terrain_classes.interval == 0;
  const bool class_pass = classify || class_fields_stale_;
  in.classify = classify;
  // gridded rain: the rate of the step's midpoint in the rain_factor field, and its volume
  const double rain_volume_rate = rain_grid_.empty() ? 0.0 : set_rain_grid(time_ + 0.5 * dt);
  // gridded air temperature: the bands at the step's midpoint in the air_temperature field
  if (!temperature_grid_.empty())
    if (auto T = temperature_grid_.values_if_changed(time_ + 0.5 * dt))
      backend_->set_field_rows(FieldId::air_temperature, terrain_.row0, terrain_.end_row(), *T);
  backend_->begin_step(in);
  for (const auto& pass : passes())
    if (pass.front() != Process::terrain_class || class_pass) backend_->run_pass(pass);
  class_fields_stale_ = false;
  StepResult result = backend_->end_step();  // the step's one wait
  const StepTally& tally = result.tally;
  time_ += dt;
  ++steps_;
  stats_ = result.stats;
  stale_ = false;  // (coast_depth_ keeps the bed of the last refresh: see model.md section 5)
  probes_ = std::move(result.probes);
  probes_current_ = true;
  measure_sections(result, dt);

  double added = 0.0, sediment_added = 0.0;
  for (const auto& p : in.points) added += p.volume, sediment_added += p.sediment;
  ledger_.rain += rain_grid_.empty() ? in.rain_rate * dt * rain_area_ : rain_volume_rate * dt;
  ledger_.inflow += added;
  ledger_.sediment_inflow += sediment_added;
  for (const auto& t : tally_table()) ledger_.*t.ledger += tally.*t.step;
  ledger_.water = stats_.water_volume;
  ledger_.material = stats_.material_volume;

  diag_ = diagnostics_now(dt);
  // Check after the books are updated, so a caller catching the error sees this step.
  check_stability(dt);
}

void Simulation::measure_sections(const StepResult& result, double dt) {
  if (section_state_.empty()) return;
  std::vector<double> q(section_state_.size(), 0.0), qs(section_state_.size(), 0.0);
  const auto& faces = sections_.faces;
  for (std::size_t j = 0; j < faces.size() && j < result.face_water.size(); ++j) {
    const auto s = static_cast<std::size_t>(sections_.section[j]);
    q[s] += sections_.sign[j] * result.face_water[j];
    qs[s] += sections_.sign[j] * result.face_sediment[j];
  }
  for (std::size_t s = 0; s < section_state_.size(); ++s) {
    SectionState& st = section_state_[s];
    st.discharge = q[s];
    st.sediment_flux = qs[s];
    st.volume += q[s] * dt;
    st.sediment_volume += qs[s] * dt;
    if (!sections_measured_ || q[s] > st.peak_discharge) {
      st.peak_discharge = q[s];
      st.peak_time = time_;
    }
  }
  sections_measured_ = true;
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
