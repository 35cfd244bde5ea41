// erodem tests — small analytical scenarios built directly from Terrain + Params, shared by
// the physics tests of every backend.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <ostream>
#include <string>

#include "erodem/backends.hpp"
#include "erodem/simulation.hpp"

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

}  // namespace erodem::test
