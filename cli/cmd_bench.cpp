// `erodem bench`: cell-steps per second of each process and of the full step, per backend,
// measured in one run, set against a byte model of each process and the memory bandwidth
// measured in the same run (docs/performance.md).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "bandwidth.hpp"
#include "commands.hpp"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/process.hpp"
#include "erodem/resident.hpp"
#include "erodem/schema.hpp"
#include "erodem/simulation.hpp"
#include "erodem/terrain_synth.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace {

struct BenchOptions {
  std::string dem;
  double cell_size = 0.0, z_scale = 1.0;
  int size = 1024;
  long steps = 20;
  std::string backends = "cpu";
  std::string threads = "0";
  std::vector<std::string> sets;   ///< --set key=value on the bench scenario
  long stream_floats = 64L << 20;  ///< elements per array of the bandwidth probe
  bool json = false;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// The benchmark run: every process on, water everywhere, rain falling; then the options'
/// `--set key=value` (the config schema's keys and value checks: flow.scheme, ...).
Params bench_params(const BenchOptions& o) {
  Params p;
  p.flow.scheme = FlowScheme::local_inertial;
  p.time.adaptive = false;
  p.time.dt = 0.5;
  p.initial.water_depth.value = 0.2;
  p.rain.rate = 20e-3 / 3600;
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::mei;  // the capacity law these figures were recorded with
  p.thermal.enabled = true;
  p.evaporation.rate = 1e-7;
  for (const auto& kv : o.sets) apply_setting(p, kv);  // each value checked as in a config
  return p;
}

// ---- the byte model ---------------------------------------------------------------------
//
// The bytes each process must move per cell and step, from the fields its sweeps read and
// write in the process table (core/include/erodem/process.hpp, sweep_bytes): every distinct
// field a sweep reads, once, plus every field it writes, once; 4 bytes per float32 field (8 in
// float64), 1 byte for the cell kind; neighbour reads once, per-row arrays and halo or point
// sweeps not counted, no write-allocate traffic (as STREAM counts). "stats" is the driver's
// reduction after every step. The OpenCL backend moves the same fields, plus the face fields
// of its local-inertial face pass and per-group partial tallies, not counted here.

/// The statistics' bytes per cell on `backend`: without the bed, its residual and the sediment
/// where the backend keeps their volumes and no process of the step changes them
/// (Backend::keeps_material_volumes, changes_material).
int stats_bytes(const Backend& backend, const Params& p) {
  const int real = p.numerics.precision == Precision::float64 ? 8 : 4;
  bool material = !backend.keeps_material_volumes();
  for (const Process q : step_sequence(p)) material = material || changes_material(q, p);
  return sweep_bytes(stats_sweep(material), real).total();
}

/// The bytes per cell of `process` (a process table name, or "stats") on `backend`.
int bytes_per_cell(const std::string& process, const Backend& backend, const Params& p) {
  const int real = p.numerics.precision == Precision::float64 ? 8 : 4;
  if (process == "stats") return stats_bytes(backend, p);
  for (const auto& e : process_table())
    if (process == e.name) return process_bytes(e.id, p, real).total();
  return 0;
}

/// The bytes per cell of the full step run in `passes` on `backend`: each part of a pass that
/// the backend fuses (Backend::fused_parts) counts its fields once (pass_sweep), any other
/// process its sweeps; plus the statistics.
int full_step_bytes(const std::vector<std::vector<Process>>& passes, const Backend& backend,
                    const Params& p) {
  const int real = p.numerics.precision == Precision::float64 ? 8 : 4;
  int bytes = stats_bytes(backend, p);
  for (const auto& pass : passes)
    for (const auto& part : backend.fused_parts(pass))
      bytes += part.size() > 1 ? sweep_bytes(pass_sweep(part, p), real).total()
                               : process_bytes(part.front(), p, real).total();
  return bytes;
}

/// What one run held: the rise of the peak resident set from before the simulation was built
/// to the end of its timing (setup included), and its device buffers.
struct Memory {
  std::string run;
  std::vector<KernelTime> kernels;  ///< device time per kernel (ERODEM_OPENCL_PROFILE=1)
  double peak_bytes = 0;            ///< VmHWM rise (bytes); 0 where /proc cannot say
  double device_bytes = 0;          ///< Backend::device_bytes()
  double cells = 1;
};

struct Row {
  std::string backend, device, process;
  int threads = 0;  ///< requested CPU threads (0: all cores); 0 for OpenCL
  int bytes = 0;    ///< bytes per cell of the byte model
  double seconds_per_step = 0, cell_steps_per_second = 0;
  double gbs() const { return bytes * cell_steps_per_second / 1e9; }
};

constexpr int kRepetitions = 3;

/// A run's short label: "cpu/2" (threads; "all" for 0), "opencl".
std::string run_label(const std::string& backend, int threads) {
  return backend == "cpu" ? fmt::format("cpu/{}", threads ? std::to_string(threads) : "all")
                          : backend;
}
std::string run_label(const Row& r) {
  return run_label(r.backend, r.threads);
}

/// Times `backend` on `terrain`; a round of `probe` runs before each timed repetition.
std::vector<Row> bench_one(const Terrain& terrain, const Params& p, const std::string& backend,
                           int threads, long steps, BandwidthProbe& probe, Memory& memory) {
  // the peak resident set from here: the backend's setup, its state and the steps
  const bool peak_known = reset_peak_resident();
  const double resident0 = resident_bytes();
  Simulation sim(terrain, p, make_backend(backend, terrain, p));
  const auto seq = sim.sequence();
  const double cells = static_cast<double>(terrain.grid.cells());
  sim.step(3);  // warm-up: kernel builds, caches, page faults
  sim.backend().finish();
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  // Per repetition and process: seconds per step. Slot seq.size() is end_step (the
  // statistics, the tallies' reduction and the step's one read), the last one the full step.
  const std::size_t n_stats = seq.size(), n_full = seq.size() + 1, n_fused = seq.size() + 2,
                    n_unfused = seq.size() + 3;
  std::vector<std::vector<double>> per_step(seq.size() + 4);
  const double dt = sim.next_dt();
  for (int rep = 0; rep < kRepetitions; ++rep) {
    probe.round();
    // Each process alone, waited for; then end_step, as the driver runs it after each step.
    std::vector<double> total(seq.size() + 1, 0.0);
    Backend& b = sim.backend();
    for (long s = 0; s < steps; ++s) {
      b.begin_step(sim.inputs_for(dt));
      for (std::size_t k = 0; k < seq.size(); ++k) {
        const auto t0 = Clock::now();
        b.run(seq[k]);
        b.finish();
        total[k] += since(t0);
      }
      const auto t0 = Clock::now();
      const FieldStats st = b.end_step().stats;
      total[n_stats] += since(t0);
      if (st.bad_cell >= 0)
        throw Error(ExitCode::unstable, "bench: the benchmark state went unstable");
    }
    for (std::size_t k = 0; k <= n_stats; ++k) per_step[k].push_back(total[k] / steps);
    // Full steps as the driver runs them (with the ledger's reductions): with the config's
    // numerics.fused_sweeps, then the fused and the unfused passes, alternating which first
    auto full = [&](int fused) {
      if (fused >= 0) sim.set_fused_sweeps(fused == 1);
      const auto t0 = Clock::now();
      sim.step(steps);
      sim.backend().finish();
      return since(t0) / steps;
    };
    per_step[n_full].push_back(full(-1));
    const int first = rep % 2;
    const double t_first = full(first), t_second = full(1 - first);
    per_step[n_fused].push_back(first == 1 ? t_first : t_second);
    per_step[n_unfused].push_back(first == 1 ? t_second : t_first);
    sim.set_fused_sweeps(p.numerics.fused_sweeps);
  }
  memory.run = run_label(backend, threads);
  memory.peak_bytes = peak_known ? peak_resident_bytes() - resident0 : 0;
  memory.device_bytes = static_cast<double>(sim.backend().device_bytes());
  memory.kernels = sim.backend().kernel_times();
  memory.cells = cells;
  std::vector<Row> rows;
  const std::string device = sim.backend().device();
  const Backend& b = sim.backend();
  const int fused_bytes = full_step_bytes(step_passes(p, true), b, p),
            unfused_bytes = full_step_bytes(step_passes(p, false), b, p);
  for (std::size_t k = 0; k < per_step.size(); ++k) {
    const std::string name = k < seq.size() ? process_name(seq[k])
                             : k == n_stats ? "stats"
                             : k == n_full  ? "full_step"
                             : k == n_fused ? "full_fused"
                                            : "full_unfused";
    const int bytes = k == n_full      ? (p.numerics.fused_sweeps ? fused_bytes : unfused_bytes)
                      : k == n_fused   ? fused_bytes
                      : k == n_unfused ? unfused_bytes
                                       : bytes_per_cell(name, b, p);
    const double sps = median(per_step[k]);
    rows.push_back({backend, device, name, threads, bytes, sps, cells / sps});
  }
  return rows;
}

/// Per run (its label, as the table's), the unfused full step's time over the fused one's.
std::vector<std::pair<std::string, double>> fused_speedups(const std::vector<Row>& rows) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& f : rows) {
    if (f.process != "full_fused") continue;
    for (const auto& u : rows)
      if (u.process == "full_unfused" && u.backend == f.backend && u.threads == f.threads)
        out.emplace_back(run_label(f), u.seconds_per_step / f.seconds_per_step);
  }
  return out;
}

/// The copy bandwidth of the device memory of an OpenCL run on a device other than the CPU
/// (a GPU's), measured after the runs; gbs 0 when no such run was made.
struct DeviceMemory {
  std::string device;  ///< as Backend::device() names it: "<platform> / <device>"
  ClCopyBandwidth copy;
};

/// Measures the device memory's copy bandwidth when one of `rows` ran on an OpenCL device
/// that is not the CPU: its kernels are set against that, not against the host's memory.
DeviceMemory device_memory(const std::vector<Row>& rows, std::size_t bytes) {
  DeviceMemory out;
  auto ran_on = [&](const ClDeviceInfo& d) {
    return std::any_of(rows.begin(), rows.end(),
                       [&](const Row& r) { return r.backend != "cpu" && r.device == d.label(); });
  };
  // PoCL's device is the host: its runs stay set against the host's probe
  const auto devices = list_opencl_devices();
  if (std::none_of(devices.begin(), devices.end(),
                   [&](const ClDeviceInfo& d) { return d.type != "CPU" && ran_on(d); }))
    return out;
  ClCopyBandwidth copy = opencl_copy_bandwidth(bytes);  // the device the runs chose
  if (copy.device.type == "CPU" || !ran_on(copy.device)) return out;
  out.device = copy.device.label();
  out.copy = copy;
  return out;
}

/// The bandwidth a row is measured against: the device memory's for a run on a GPU (triad
/// not measured there: NaN); else the host's, one thread for one CPU thread, else all.
double copy_ref(const Row& r, const Bandwidth& bw, const DeviceMemory& dm) {
  if (dm.copy.gbs > 0 && r.device == dm.device) return dm.copy.gbs;
  return r.backend == "cpu" && (r.threads == 1 || bw.threads == 1) ? bw.copy_one : bw.copy_all;
}
double triad_ref(const Row& r, const Bandwidth& bw, const DeviceMemory& dm) {
  if (dm.copy.gbs > 0 && r.device == dm.device) return std::nan("");
  return r.backend == "cpu" && (r.threads == 1 || bw.threads == 1) ? bw.triad_one : bw.triad_all;
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
  if (o.stream_floats < 1024) throw Error(ExitCode::usage, "--stream-floats: expected >= 1024");
  std::vector<std::pair<std::string, int>> runs;
  for (const auto& backend : split(o.backends)) {
    if (backend != "cpu" && backend != "opencl" && backend != "auto")
      throw Error(ExitCode::usage, "--backends: '" + backend + "': expected cpu, opencl or auto");
    if (backend != "cpu") {
      runs.push_back({backend, 0});
      continue;
    }
    for (const auto& t : split(o.threads)) {
      int n = -1;
      try {
        std::size_t used = 0;
        n = std::stoi(t, &used);
        if (used != t.size()) n = -1;
      } catch (const std::exception&) {
        n = -1;
      }
      if (n < 0) throw Error(ExitCode::usage, "--threads: '" + t + "': expected an integer >= 0");
      runs.push_back({backend, n});
    }
  }
  const Params params = bench_params(o);
  std::vector<Row> rows;
  std::vector<Memory> memory;
  // Rounds of the bandwidth probe interleaved with the timed repetitions, and one at the end:
  // the kernels and the probe see the same machine.
  BandwidthProbe probe(static_cast<std::size_t>(o.stream_floats));
  for (const auto& [backend, threads] : runs) {
    Params p = params;
    p.numerics.threads = threads;
    memory.emplace_back();
    auto r = bench_one(terrain, p, backend, threads, o.steps, probe, memory.back());
    rows.insert(rows.end(), r.begin(), r.end());
  }
  probe.round();
  const Bandwidth bw = probe.result();
  const DeviceMemory dm =
      device_memory(rows, static_cast<std::size_t>(o.stream_floats) * sizeof(float) * 4);
  const bool small = bw.llc_bytes > 0 && o.stream_floats * sizeof(float) < 4 * bw.llc_bytes;

  const auto& g = terrain.grid;
  if (o.json) {
    std::printf(
        "{\"grid\": [%d, %d], \"cells\": %zu, \"steps\": %ld, \"repetitions\": %d, "
        "\"source\": %s, \"flow_scheme\": \"%s\", \"transport_scheme\": \"%s\",\n",
        g.nx, g.ny, g.cells(), o.steps, kRepetitions, json_string(terrain.source).c_str(),
        scheme_name(params.flow.scheme), scheme_name(params.transport.scheme));
    std::printf(
        " \"bandwidth\": {\"floats_per_array\": %ld, \"bytes_per_array\": %zu, "
        "\"last_level_cache_bytes\": %zu, \"below_4x_llc\": %s, \"repetitions\": %d, "
        "\"rounds\": %d, \"threads\": %d, \"copy_gbs\": %s, \"copy_gbs_lowest_round\": %s, "
        "\"copy_gbs_highest_round\": %s, \"triad_gbs\": %s, \"copy_gbs_1_thread\": %s, "
        "\"triad_gbs_1_thread\": %s},\n",
        o.stream_floats, static_cast<std::size_t>(o.stream_floats) * sizeof(float), bw.llc_bytes,
        small ? "true" : "false", bw.repetitions, bw.rounds, bw.threads,
        json_number(bw.copy_all).c_str(), json_number(bw.copy_all_low).c_str(),
        json_number(bw.copy_all_high).c_str(), json_number(bw.triad_all).c_str(),
        json_number(bw.copy_one).c_str(), json_number(bw.triad_one).c_str());
    if (dm.copy.gbs > 0)
      std::printf(
          " \"device_bandwidth\": {\"device\": %s, \"bytes_per_buffer\": %zu, "
          "\"repetitions\": %d, \"copy_gbs\": %s, \"copy_gbs_lowest\": %s, "
          "\"copy_gbs_highest\": %s},\n",
          json_string(dm.device).c_str(), dm.copy.bytes, dm.copy.repetitions,
          json_number(dm.copy.gbs).c_str(), json_number(dm.copy.gbs_low).c_str(),
          json_number(dm.copy.gbs_high).c_str());
    std::printf(" \"results\": [\n");
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& r = rows[k];
      const double c = copy_ref(r, bw, dm), t = triad_ref(r, bw, dm);
      std::printf(
          "  {\"backend\": %s, \"device\": %s, \"threads\": %d, \"process\": %s, "
          "\"seconds_per_step\": %s, \"cell_steps_per_second\": %s, \"bytes_per_cell\": %d, "
          "\"gbs\": %s, \"fraction_of_copy\": %s, \"fraction_of_triad\": %s}%s\n",
          json_string(r.backend).c_str(), json_string(r.device).c_str(), r.threads,
          json_string(r.process).c_str(), json_number(r.seconds_per_step).c_str(),
          json_number(r.cell_steps_per_second).c_str(), r.bytes, json_number(r.gbs()).c_str(),
          json_number(r.bytes ? r.gbs() / c : std::nan("")).c_str(),
          json_number(r.bytes ? r.gbs() / t : std::nan("")).c_str(),
          k + 1 < rows.size() ? "," : "");
    }
    std::printf(" ],\n \"fused_speedup\": {");
    const auto speedups = fused_speedups(rows);
    for (std::size_t k = 0; k < speedups.size(); ++k)
      std::printf("%s%s: %s", k ? ", " : "", json_string(speedups[k].first).c_str(),
                  json_number(speedups[k].second).c_str());
    std::printf("},\n \"memory\": [\n");
    for (std::size_t k = 0; k < memory.size(); ++k) {
      const auto& m = memory[k];
      std::printf(
          "  {\"run\": %s, \"peak_resident_rise_bytes\": %s, \"peak_resident_bytes_per_cell\": "
          "%s, \"device_buffer_bytes\": %s, \"device_buffer_bytes_per_cell\": %s}%s\n",
          json_string(m.run).c_str(), json_number(m.peak_bytes).c_str(),
          json_number(m.peak_bytes / m.cells).c_str(), json_number(m.device_bytes).c_str(),
          json_number(m.device_bytes / m.cells).c_str(), k + 1 < memory.size() ? "," : "");
    }
    std::printf(" ],\n \"kernel_times\": [");
    bool first = true;
    for (const auto& m : memory)
      for (const auto& k : m.kernels) {
        std::printf("%s\n  {\"run\": %s, \"kernel\": %s, \"calls\": %ld, \"seconds\": %s}",
                    first ? "" : ",", json_string(m.run).c_str(), json_string(k.name).c_str(),
                    k.calls, json_number(k.seconds).c_str());
        first = false;
      }
    std::printf("%s]}\n", first ? "" : "\n ");
    return 0;
  }
  std::printf(
      "%s: %d x %d cells, %s flow, %s transport, %ld timed steps, median of %d "
      "repetitions\n",
      terrain.source.c_str(), g.nx, g.ny, scheme_name(params.flow.scheme),
      scheme_name(params.transport.scheme), o.steps, kRepetitions);
  std::printf(
      "memory bandwidth (median of %d rounds of %d beside the runs, %.0f MiB per array%s): copy "
      "%.2f GB/s (rounds %.1f to %.1f), triad %.2f GB/s with %d thread%s; copy %.2f GB/s, "
      "triad %.2f GB/s with 1 thread\n",
      bw.rounds, bw.repetitions, o.stream_floats * 4.0 / (1024.0 * 1024.0),
      small ? ", below 4x the last-level cache: cache-resident" : "", bw.copy_all, bw.copy_all_low,
      bw.copy_all_high, bw.triad_all, bw.threads, bw.threads == 1 ? "" : "s", bw.copy_one,
      bw.triad_one);
  if (dm.copy.gbs > 0)
    std::printf(
        "device memory (%s: clEnqueueCopyBuffer, median of %d copies of %.0f MiB): copy %.1f "
        "GB/s (%.1f to %.1f); that device's runs are set against it (no triad)\n",
        dm.device.c_str(), dm.copy.repetitions, dm.copy.bytes / 1048576.0, dm.copy.gbs,
        dm.copy.gbs_low, dm.copy.gbs_high);
  // Runs by a short label; their devices listed first.
  auto label = [](const Row& r) { return run_label(r); };
  std::string last;
  for (const auto& r : rows)
    if (label(r) != last) {
      last = label(r);
      std::printf("  %-10s %s\n", last.c_str(), r.device.c_str());
    }
  std::printf("%-10s %-12s %10s %14s %6s %8s %7s %7s\n", "run", "process", "ms/step",
              "cell-steps/s", "B/cell", "GB/s", "%copy", "%triad");
  for (const auto& r : rows) {
    const double c = copy_ref(r, bw, dm), t = triad_ref(r, bw, dm);
    if (r.bytes)
      std::printf("%-10s %-12s %10.3f %14.4g %6d %8.2f %6.0f%% %7s\n", label(r).c_str(),
                  r.process.c_str(), 1e3 * r.seconds_per_step, r.cell_steps_per_second, r.bytes,
                  r.gbs(), 100 * r.gbs() / c,
                  std::isnan(t) ? "-" : fmt::format("{:.0f}%", 100 * r.gbs() / t).c_str());
    else
      std::printf("%-10s %-12s %10.3f %14.4g %6s %8s %7s %7s\n", label(r).c_str(),
                  r.process.c_str(), 1e3 * r.seconds_per_step, r.cell_steps_per_second, "-", "-",
                  "-", "-");
  }
  for (const auto& [run, s] : fused_speedups(rows))
    std::printf("%s: fused passes %.2fx the unfused full step (full_unfused / full_fused time)\n",
                run.c_str(), s);
  for (const auto& m : memory)
    std::printf("%s: peak resident set +%.1f MiB from before the setup (%.1f B/cell)%s\n",
                m.run.c_str(), m.peak_bytes / 1048576.0, m.peak_bytes / m.cells,
                m.device_bytes > 0
                    ? fmt::format(", device buffers {:.1f} MiB ({:.1f} B/cell)",
                                  m.device_bytes / 1048576.0, m.device_bytes / m.cells)
                          .c_str()
                    : "");
  // ERODEM_OPENCL_PROFILE=1: the device time of each kernel and of the reads, over the whole
  // run (warm-up, per-process and full steps), from the profiling events
  for (const auto& m : memory) {
    if (m.kernels.empty()) continue;
    double total = 0;
    for (const auto& k : m.kernels) total += k.seconds;
    auto kernels = m.kernels;
    std::sort(kernels.begin(), kernels.end(),
              [](const KernelTime& a, const KernelTime& b) { return a.seconds > b.seconds; });
    std::printf("%s: device time per kernel over the run (%.1f ms in all):\n", m.run.c_str(),
                1e3 * total);
    std::printf("  %-36s %8s %10s %12s %7s\n", "kernel", "calls", "ms", "us per call", "share");
    for (const auto& k : kernels)
      std::printf("  %-36s %8ld %10.3f %12.2f %6.1f%%\n", k.name.c_str(), k.calls, 1e3 * k.seconds,
                  k.calls ? 1e6 * k.seconds / static_cast<double>(k.calls) : 0.0,
                  total > 0 ? 100 * k.seconds / total : 0.0);
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
  sub->add_option("--stream-floats", o->stream_floats,
                  "Floats per array of the memory-bandwidth probe (3 arrays; default 64Mi)");
  sub->add_option("--set", o->sets,
                  "Override a key of the bench scenario: key=value (repeatable), e.g. "
                  "flow.scheme=pipes");
  sub->add_flag("--json", o->json, "Machine-readable output");
  return [o] { return bench(*o); };
}

}  // namespace erodem::cli
