// `erodem bench`: cell-steps per second of each process and of the full step, per backend,
// measured in one run.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>

#include "commands.hpp"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/simulation.hpp"
#include "erodem/terrain_synth.hpp"

namespace erodem::cli {

namespace {

struct BenchOptions {
  std::string dem;
  double cell_size = 0.0, z_scale = 1.0;
  int size = 1024;
  long steps = 20;
  std::string backends = "cpu";
  std::string threads = "0";
  bool json = false;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// The benchmark run: every process on, water everywhere, rain falling.
Params bench_params() {
  Params p;
  p.flow.scheme = FlowScheme::local_inertial;
  p.time.adaptive = false;
  p.time.dt = 0.5;
  p.initial.water_depth.value = 0.2;
  p.rain.rate = 20e-3 / 3600;
  p.erosion.enabled = true;
  p.thermal.enabled = true;
  p.evaporation.rate = 1e-7;
  return p;
}

struct Row {
  std::string backend, device, process;
  double seconds_per_step = 0, cell_steps_per_second = 0;
};

std::vector<Row> bench_one(const Terrain& terrain, Params p, const std::string& backend,
                           long steps) {
  auto be = make_backend(backend, terrain, p);
  Simulation sim(terrain, p, std::move(be));
  const auto seq = sim.sequence();
  const double cells = static_cast<double>(terrain.grid.cells());
  sim.step(3);  // warm-up: kernel builds, caches, page faults
  sim.backend().finish();
  std::vector<double> per_process(seq.size(), 0.0);
  using Clock = std::chrono::steady_clock;
  const double dt = sim.next_dt();
  // Per process: each one run alone, waited for.
  for (long s = 0; s < steps; ++s) {
    const StepInputs in = sim.inputs_for(dt);
    StepTally tally;
    for (std::size_t k = 0; k < seq.size(); ++k) {
      const auto t0 = Clock::now();
      sim.backend().run(seq[k], in, tally);
      sim.backend().finish();
      per_process[k] += std::chrono::duration<double>(Clock::now() - t0).count();
    }
  }
  // Full steps as the driver runs them (with the ledger's reductions).
  const auto t0 = Clock::now();
  sim.step(steps);
  sim.backend().finish();
  const double full = std::chrono::duration<double>(Clock::now() - t0).count() / steps;
  std::vector<Row> rows;
  const std::string device = sim.backend().device();
  for (std::size_t k = 0; k < seq.size(); ++k) {
    const double sps = per_process[k] / steps;
    rows.push_back({backend, device, process_name(seq[k]), sps, cells / sps});
  }
  rows.push_back({backend, device, "full_step", full, cells / full});
  return rows;
}

int bench(const BenchOptions& o) {
  Terrain terrain;
  if (!o.dem.empty()) {
    Params::Dem d;
    d.path = o.dem;
    d.cell_size = o.cell_size;
    d.z_scale = o.z_scale;
    terrain = io::read_dem(d);
  } else {
    Params::Dem d;
    d.synthetic = "fbm";
    d.size = o.size;
    d.cell_size = 10.0;
    d.relief = 200.0;
    terrain = make_synthetic_terrain(d);
  }
  if (o.steps < 1) throw Error(ExitCode::usage, "--steps: expected at least 1");
  std::vector<Row> rows;
  for (const auto& backend : split(o.backends)) {
    const auto thread_list = backend == "cpu" ? split(o.threads) : std::vector<std::string>{"0"};
    for (const auto& t : thread_list) {
      Params p = bench_params();
      p.numerics.threads = std::stoi(t);
      auto r = bench_one(terrain, p, backend, o.steps);
      rows.insert(rows.end(), r.begin(), r.end());
    }
  }
  const auto& g = terrain.grid;
  if (o.json) {
    std::printf("{\"grid\": [%d, %d], \"steps\": %ld, \"source\": \"%s\", \"results\": [\n", g.nx,
                g.ny, o.steps, terrain.source.c_str());
    for (std::size_t k = 0; k < rows.size(); ++k)
      std::printf(
          "  {\"backend\": \"%s\", \"device\": \"%s\", \"process\": \"%s\", "
          "\"seconds_per_step\": %.6e, \"cell_steps_per_second\": %.6e}%s\n",
          rows[k].backend.c_str(), rows[k].device.c_str(), rows[k].process.c_str(),
          rows[k].seconds_per_step, rows[k].cell_steps_per_second, k + 1 < rows.size() ? "," : "");
    std::printf("]}\n");
  } else {
    std::printf("%s: %d x %d cells, %ld timed steps\n", terrain.source.c_str(), g.nx, g.ny,
                o.steps);
    std::printf("%-38s %-12s %14s %18s\n", "device", "process", "ms/step", "cell-steps/s");
    for (const auto& r : rows)
      std::printf("%-38s %-12s %14.3f %18.4g\n", r.device.c_str(), r.process.c_str(),
                  1e3 * r.seconds_per_step, r.cell_steps_per_second);
  }
  return 0;
}

}  // namespace

Action add_bench(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* sub = app.add_subcommand("bench", "Cell-steps per second per backend and process");
  auto* dem = sub->add_option("--dem", o->dem, "DEM file (default: synthetic fbm terrain)");
  sub->add_option("--size", o->size, "Synthetic grid size (cells per side)")
      ->check(CLI::Range(8, 32768))
      ->excludes(dem);
  sub->add_option("--cell-size", o->cell_size, "Cell size (m) for a DEM without georeferencing");
  sub->add_option("--z-scale", o->z_scale, "Multiplier of the DEM's stored values");
  sub->add_option("--steps", o->steps, "Timed steps");
  sub->add_option("--backends", o->backends, "Comma-separated backends (cpu, opencl)");
  sub->add_option("--threads", o->threads,
                  "Comma-separated CPU thread counts to measure (0 = all cores)");
  sub->add_flag("--json", o->json, "Machine-readable output");
  return [o] { return bench(*o); };
}

}  // namespace erodem::cli
