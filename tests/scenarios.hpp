// erodem tests — small analytical scenarios built directly from Terrain + Params, shared by
// the physics tests of every backend.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/process.hpp"
#include "erodem/simulation.hpp"
#include "reference_solutions.hpp"

namespace erodem::test {

/// What a test runs on: a backend name and a precision.
struct Target {
  std::string backend;
  Precision precision;
  bool f64() const { return precision == Precision::float64; }
  std::string label() const { return backend + (f64() ? "_float64" : "_float32"); }
};

/// gtest prints a Target by its label (test names and failure messages).
inline void PrintTo(const Target& t, std::ostream* os) {
  *os << t.label();
}

inline Simulation make_simulation(Terrain terrain, Params params, const Target& target) {
  params.numerics.precision = target.precision;
  auto backend = make_backend(target.backend, terrain, params);
  return Simulation(std::move(terrain), std::move(params), std::move(backend));
}

/// Big Tujunga (SRTM 30 m, UTM 11N) from the shared DEMs.
inline std::string tujunga_path() {
  return std::string(ERODEM_SHARED_DIR) + "/data/dem/big_tujunga/srtm_bigtujunga30m_utm11.tif";
}

/// A storm on a 256 x 256 crop of Big Tujunga with every process on: 720 mm/h of rain (it
/// makes channels flow within 1,000 steps), erosion, `transport`, thermal collapse,
/// evaporation, open edges; fixed steps of `dt` seconds, or adaptive ones up to `dt`.
/// The scenario the backend-agreement and instruction-set tests compare fields on.
inline Params tujunga_storm(FlowScheme flow, TransportScheme transport, bool adaptive, double dt,
                            Precision precision) {
  Params p;
  p.dem.path = tujunga_path();
  p.dem.window = std::array<int, 4>{420, 180, 256, 256};
  p.flow.scheme = flow;
  p.flow.manning_n.value = 0.035;
  p.time.adaptive = adaptive;
  p.time.dt = dt;
  p.time.dt_max = dt;
  p.rain.rate = 2e-4;  // m/s (720 mm/h)
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::mei;  // the capacity law these figures were recorded with
  p.erosion.sediment_capacity = 0.5;
  p.transport.scheme = transport;
  p.thermal.enabled = true;
  p.thermal.talus_angle = 35.0;
  p.evaporation.rate = 1e-6;
  p.boundary.north = p.boundary.south = p.boundary.east = p.boundary.west = BoundaryKind::open;
  p.numerics.precision = precision;
  p.numerics.wetness_time = 600.0;
  return p;
}

/// A flat projected grid of nx x ny square cells of `cell` metres, bed at 0 m.
inline Terrain flat_terrain(int nx, int ny, double cell) {
  Terrain t;
  t.grid = Grid::uniform(nx, ny, cell);
  t.bed.assign(t.grid.cells(), 0.0);
  t.source = "test";
  return t;
}

/// A bumpy bed between about 2 and 8 m with one island rising to 14 m (above a 10 m lake).
inline Terrain bumpy_terrain(int n, double cell) {
  Terrain t = flat_terrain(n, n, cell);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double x = c * cell, y = r * cell;
      const double rr = std::hypot(c - 0.3 * n, r - 0.6 * n) / (0.1 * n);
      t.bed[static_cast<std::size_t>(r) * n + c] =
          5.0 + 3.0 * std::sin(x / 37.0) * std::cos(y / 23.0) + 9.0 * std::exp(-rr * rr);
    }
  return t;
}

/// The default parameters, one object (a Params temporary per default value makes GCC 12
/// warn of its strings, falsely).
inline const Params& default_params() {
  static const Params p;
  return p;
}

/// The water volume (m^3) and the area (m^2) of the cells north [0] and south [1] of row
/// `divide` of `sim`'s grid (the row itself, a wall, left out): two basins' budgets.
struct Basins {
  double volume[2] = {0, 0}, area[2] = {0, 0};
};
inline Basins basin_volumes(const Simulation& sim, int divide) {
  const Grid& g = sim.grid();
  const auto d = sim.field(FieldId::water_depth);
  Basins b;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) {
      if (r == divide) continue;
      b.volume[r > divide] += d[static_cast<std::size_t>(r) * g.nx + c] * g.area[r];
      b.area[r > divide] += g.area[r];
    }
  return b;
}

/// Parameters with every process off and closed boundaries.
inline Params quiet_params(FlowScheme scheme, double dt) {
  Params p;
  p.flow.scheme = scheme;
  p.flow.manning_n.value = 0.0;
  p.time.dt = dt;
  p.time.adaptive = false;
  p.erosion.enabled = false;
  p.thermal.enabled = false;
  p.evaporation.rate = 0.0;
  p.rain.rate = 0.0;
  return p;
}

// ---- dam breaks -----------------------------------------------------------------------

/// A 1-D dam break: a channel of `n` cells of `dx` m along x (3 rows between closed walls),
/// water `h_up` m deep upstream of the dam at `x_dam` m from the west wall and `h_down`
/// downstream, flat frictionless bed.
struct DamBreak {
  int n;
  double dx, x_dam, h_up, h_down;
  /// The channel's middle row, x measured from the dam.
  Row row() const { return Row{n, dx, -x_dam}; }
  Terrain terrain() const {
    Terrain t = flat_terrain(n, 3, dx);
    t.water_depth.assign(t.grid.cells(), 0.0);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < n; ++c)
        t.water_depth[static_cast<std::size_t>(r) * n + c] = row().centre(c) < 0 ? h_up : h_down;
    return t;
  }
  std::vector<double> initial_depth() const {
    return row().sample([&](double x) { return x < 0 ? h_up : h_down; });
  }
};

/// The middle row of a field of a 3-row channel.
inline std::vector<double> middle_row(const Simulation& sim, FieldId id) {
  const auto f = sim.field(id);
  const int nx = sim.grid().nx;
  return std::vector<double>(f.begin() + nx, f.begin() + 2 * nx);
}

/// A dam break's middle row after `t_end` s with `params`' fixed steps.
struct DamBreakResult {
  std::vector<double> depth, velocity;  ///< m, m/s (velocity_x)
  double time = 0;                      ///< s
  double water_drift = 0;               ///< relative change of the water volume
};

inline DamBreakResult run_dam_break(const DamBreak& db, const Params& params, double t_end,
                                    const Target& target) {
  auto sim = make_simulation(db.terrain(), params, target);
  sim.step(static_cast<long>(t_end / params.time.dt + 0.5));
  const auto& L = sim.ledger();
  return {middle_row(sim, FieldId::water_depth), middle_row(sim, FieldId::velocity_x), sim.time(),
          std::abs(L.water - L.water_initial) / L.water_initial};
}

// ---- uniform flow down a plane ---------------------------------------------------------

/// A channel of `n` cells of `dx` m (3 rows) of slope `slope` falling eastwards to an open
/// outlet, Manning n `manning`, fed with `q` m^2/s by a line inflow across the first column,
/// starting at half the normal depth (q n / sqrt S)^(3/5). Local inertial.
struct ManningPlane {
  int n = 200;
  double dx = 10.0, slope = 1e-3, manning = 0.03, q = 0.5;
  double normal_depth() const { return std::pow(q * manning / std::sqrt(slope), 0.6); }
  Terrain terrain() const {
    Terrain t = flat_terrain(n, 3, dx);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < n; ++c)
        t.bed[static_cast<std::size_t>(r) * n + c] = slope * (n - c - 0.5) * dx;
    t.water_depth.assign(t.grid.cells(), 0.5 * normal_depth());
    return t;
  }
  /// Fixed steps of `dt` s (the caller may make them adaptive).
  Params params(double dt) const {
    Params p = quiet_params(FlowScheme::local_inertial, dt);
    p.flow.manning_n.value = manning;
    p.boundary.east = BoundaryKind::open;
    const double width = 3 * dx;
    p.inflow.push_back(InflowSpec{{{0.5 * dx, 0.0}, {0.5 * dx, width}}, {{0.0, q * width}}});
    return p;
  }
};

// ---- processes run on a state held fixed ----------------------------------------------

/// Sets a uniform flow eastwards on every cell: depth `h` (m), velocity_x `u` (m/s),
/// velocity_y 0, and the outflow u h dy (m^3/s) through every east face (the last column's
/// into the east ghost), none through the others. With the flow and water processes left out
/// (run_processes) it stays so: the state erosion and transport see is held fixed.
inline void set_uniform_flow(Simulation& sim, double h, double u) {
  const Grid& g = sim.grid();
  std::vector<double> east(g.cells());
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) east[static_cast<std::size_t>(r) * g.nx + c] = u * h * g.dy[r];
  const std::vector<double> zero(g.cells(), 0.0);
  auto& b = sim.backend();
  b.set_field(FieldId::water_depth, std::vector<double>(g.cells(), h));
  b.set_field(FieldId::velocity_x, std::vector<double>(g.cells(), u));
  b.set_field(FieldId::velocity_y, zero);
  b.set_field(FieldId::flux_right, east);
  b.set_field(FieldId::flux_left, zero);
  b.set_field(FieldId::flux_top, zero);
  b.set_field(FieldId::flux_bottom, zero);
}

/// Runs only `processes` of the simulation's backend, `steps` times with steps of `dt` s
/// (Simulation::step always runs flow and water; Backend::run runs one process): every field
/// the processes do not write stays as set. Returns the volumes that crossed the boundary,
/// summed over the steps. The simulation's time and ledger are left as they were.
inline StepTally run_processes(Simulation& sim, const std::vector<Process>& processes, double dt,
                               long steps) {
  StepTally tally;
  StepInputs in;
  in.dt = dt;
  Backend& be = sim.backend();
  for (long k = 0; k < steps; ++k) {
    in.t = k * dt;
    in.air_temperature = sim.air_temperature_at(in.t + 0.5 * dt);
    be.begin_step(in);
    for (Process p : processes) be.run(p);
    const StepTally step = be.end_step().tally;
    for (const auto& t : tally_table()) tally.*t.step += step.*t.step;
  }
  return tally;
}

/// Suspended sediment adapting to the capacity along a uniform flow held fixed: a channel of
/// `length` m of `dx` m cells (3 rows), flat bed at 0, depth `depth`, speed `speed` eastwards,
/// clear water entering through the west wall's face. Capacity C = K_c sin_min u (flat bed:
/// the tilt's floor min_tilt applies), eroded at K_s with hardness 1. Steps of
/// `courant` dx / u; erosion and transport only (run_processes).
struct SedimentAdaptation {
  double length = 100.0, depth = 1.0, speed = 1.0;   // m, m, m/s
  double capacity_k = 0.02, dissolving_rate = 0.05;  // K_c (s), K_s (1/s)
  double courant = 0.4;                              // u dt / dx
  double capacity() const {
    static const Params defaults;  // (a Params temporary made GCC 12 warn: schema_kinds.cpp)
    return capacity_k * defaults.erosion.min_tilt * speed;
  }
  /// K_s dx / u: the adaptation length u / K_s in cells, inverted.
  double resolution(double dx) const { return dissolving_rate * dx / speed; }
  Params params(TransportScheme scheme, double dx) const {
    Params p = quiet_params(FlowScheme::local_inertial, courant * dx / speed);
    p.erosion.enabled = true;
    p.erosion.law = ErosionLaw::mei;  // the capacity law these figures were recorded with
    p.erosion.sediment_capacity = capacity_k;
    p.erosion.dissolving_rate = dissolving_rate;
    p.transport.scheme = scheme;
    return p;
  }
  struct Result {
    Row row;
    std::vector<double> sediment;  ///< middle row (m)
    double material_closure;       ///< |sum (b + s) area + sediment out| / sum |b0 - b| area
  };
  /// Runs `duration` s and returns the middle row's sediment.
  Result run(TransportScheme scheme, double dx, double duration, const Target& target) const {
    const int n = static_cast<int>(length / dx + 0.5);
    const Params p = params(scheme, dx);
    auto sim = make_simulation(flat_terrain(n, 3, dx), p, target);
    set_uniform_flow(sim, depth, speed);
    const auto tally = run_processes(sim, {Process::erosion, Process::transport}, p.time.dt,
                                     static_cast<long>(duration / p.time.dt + 0.5));
    const auto bed = sim.field(FieldId::bed);
    double moved = 0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < n; ++c) moved += std::abs(bed[static_cast<std::size_t>(r) * n + c]);
    moved *= dx * dx;
    const double material = sim.backend().stats().material_volume;
    return {Row{n, dx, 0.0}, middle_row(sim, FieldId::sediment),
            std::abs(material + tally.sediment_out - tally.transport_change) / moved};
  }
};

/// Sum of a row-major field times the cell areas (m^3 for a field in m).
inline double volume_of(const Grid& g, const std::vector<double>& field) {
  double v = 0;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) v += field[static_cast<std::size_t>(r) * g.nx + c] * g.area[r];
  return v;
}

}  // namespace erodem::test
