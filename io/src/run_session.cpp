// erodem — the one run driver (see run_session.hpp).
#include "erodem/io/run_session.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/paths.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/parameter_rasters.hpp"
#include "erodem/schema.hpp"
#include "erodem/units.hpp"

namespace erodem::io {

namespace {

/// Whether `p` reads any parameter raster (those are loaded on the DEM's grid by
/// load_terrain, so a terrain loaded without them cannot be used as it is).
bool has_parameter_rasters(const Params& p) {
  for (const auto& r : parameter_rasters())
    if (!parameter_raster_path(r, p).empty()) return true;
  return !p.rain.grids.empty() || !p.snow.temperature_grids.empty();
}

/// The stored state of `reader` at `time` (an index of restart_times(); the last one when no
/// time is given). Times match to 1e-6 relative or 1 ms, since a time on a command line is
/// rounded.
std::size_t restart_index(const ResultReader& reader, std::optional<double> time,
                          const std::string& label) {
  const auto times = reader.restart_times();
  if (times.empty()) {
    if (reader.times().empty()) throw Error(ExitCode::data, reader.path() + ": holds no snapshot");
    reader.restart_header(0);  // throws: no restart state, and how to get one
  }
  if (!time) return times.size() - 1;
  std::size_t i = 0;
  for (std::size_t k = 1; k < times.size(); ++k)
    if (std::abs(times[k] - *time) < std::abs(times[i] - *time)) i = k;
  if (std::abs(times[i] - *time) <= std::max(1e-3, 1e-6 * std::abs(*time))) return i;
  std::string list;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (times.size() > 50 && k == 25) {  // long lists: the first and last 25
      list += ", ...";
      k = times.size() - 25;
    }
    list += fmt::format("{}{:.10g}", list.empty() ? "" : ", ", times[k]);
  }
  const bool snapshot = std::any_of(reader.times().begin(), reader.times().end(), [&](double t) {
    return std::abs(t - *time) <= std::max(1e-3, 1e-6 * std::abs(*time));
  });
  throw Error(ExitCode::usage,
              fmt::format("{} {}:{:.10g}: {}; the file holds the state at t = {} s ({} time{})",
                          label, reader.path(), *time,
                          snapshot ? "that snapshot has no stored state (output.restart_every)"
                                   : "no snapshot at that time",
                          list, times.size(), times.size() == 1 ? "" : "s"));
}

/// "section.key = value" of a TOML text written by dump_toml, one entry per key line.
std::map<std::string, std::string> config_entries(const std::string& toml) {
  std::map<std::string, std::string> out;
  std::istringstream in(toml);
  std::string line, section;
  std::map<std::string, int> arrays;  // [[inflow]] tables are numbered
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("[[", 0) == 0) {
      const std::string name = line.substr(2, line.find("]]") - 2);
      section = fmt::format("{}[{}]", name, arrays[name]++);
    } else if (line[0] == '[') {
      section = line.substr(1, line.find(']') - 1);
    } else if (const auto eq = line.find(" = "); eq != std::string::npos) {
      out[section + "." + line.substr(0, eq)] = line.substr(eq + 3);
    }
  }
  return out;
}

/// The keys (besides time.* and output.*, which a restart may change) whose values differ.
std::vector<std::string> changed_keys(const std::string& stored, const std::string& now) {
  const auto a = config_entries(stored), b = config_entries(now);
  std::set<std::string> keys;
  for (const auto& [k, v] : a) keys.insert(k);
  for (const auto& [k, v] : b) keys.insert(k);
  std::vector<std::string> out;
  for (const auto& k : keys) {
    if (k.rfind("time.", 0) == 0 || k.rfind("output.", 0) == 0) continue;
    const auto ia = a.find(k), ib = b.find(k);
    if (ia == a.end() || ib == b.end() || ia->second != ib->second) out.push_back(k);
  }
  return out;
}

}  // namespace

std::pair<std::string, std::optional<double>> split_restart(const std::string& arg) {
  const auto colon = arg.rfind(':');
  if (colon != std::string::npos && colon + 1 < arg.size()) {
    if (auto t = try_parse_quantity(arg.substr(colon + 1), Dimension::time))
      return {arg.substr(0, colon), *t};
  }
  return {arg, std::nullopt};
}

Params stored_params(const std::string& restart_arg) {
  const std::string file = split_restart(restart_arg).first;
  const ResultReader reader(file);
  const std::string text = reader.attribute("config_toml");
  if (text.empty())
    throw Error(ExitCode::data, file + ": holds no config (root attribute config_toml)");
  toml::table table;
  try {
    table = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw Error(ExitCode::data, fmt::format("{}: its config_toml does not parse: {}", file,
                                            std::string(e.description())));
  }
  return params_from_toml(table, file + " (config_toml)");
}

RunSession::RunSession(Params params, SessionOptions options) : options_(std::move(options)) {
  // The output can be created: checked before the (possibly long) reading of the inputs.
  if (options_.write) check_output_path(params.output.path, options_.overwrite);
  // MPI with parallel HDF5: every rank opens the one file, so every rank must see its folder
  if (options_.write && collective_files()) check_output_folder_shared(params.output.path);
  if (options_.terrain && !has_parameter_rasters(params)) {
    Terrain t = *options_.terrain;
    auto backend = make_backend(options_.backend, t, params);
    sim_ = std::make_unique<Simulation>(std::move(t), params, std::move(backend));
  } else {
    sim_ = std::make_unique<Simulation>(make_simulation(params, options_.backend));
  }
  if (!options_.restart.empty()) restore(options_.restart);
  first_step_ = sim_->steps_done();
  if (options_.on_built) options_.on_built(*this);
  if (options_.write) open_output(sim_->params(), options_.overwrite);
}

RunSession::~RunSession() = default;

void RunSession::restore(const std::string& arg) {
  const auto [file, time] = split_restart(arg);
  const ResultReader reader(file);
  const auto& g = reader.grid();
  Simulation& sim = *sim_;
  if (g.nx != sim.grid().nx || g.ny != sim.grid().ny)
    throw Error(
        ExitCode::data,
        fmt::format("{} {}: the stored run is on a {} x {} grid, this config gives "
                    "{} x {}",
                    options_.restart_label, file, g.nx, g.ny, sim.grid().nx, sim.grid().ny));
  const std::size_t index = restart_index(reader, time, options_.restart_label);
  sim.restore(reader.restart_header(index), [&reader, index](FieldId id, int row0, int row1) {
    return reader.restart_rows(index, id, row0, row1);
  });
  const auto changed = changed_keys(reader.attribute("config_toml"), dump_toml(sim.params()));
  if (!changed.empty())
    warnings_.push_back(
        fmt::format("restarting with a config that differs from the stored run's in: {}",
                    fmt::join(changed, ", ")));
  if (reader.attribute("backend") != sim.backend().name())
    warnings_.push_back(
        fmt::format("the stored run used the {} backend, this one {}: not bit "
                    "for bit",
                    reader.attribute("backend"), sim.backend().name()));
  restart_from_ = fmt::format("{}:{:.17g}", file, sim.time());
}

void RunSession::open_output(const Params& output_params, bool overwrite) {
  close_output();
  Provenance provenance = Provenance::of(*sim_, options_.command_line);
  provenance.config_toml = dump_toml(output_params);
  provenance.restart_from = restart_from_;
  // Results go to a temporary file beside the output (flushed at every snapshot) that is
  // renamed into place when the run completes.
  writer_ = std::make_unique<ResultWriter>(output_params.output.path, sim_->grid(), output_params,
                                           provenance, overwrite);
  // the gauges sampled with every step (on OpenCL on the device, in the step's one read)
  sim_->set_probes(writer_->gauge_cells(), writer_->gauge_fields());
  writer_->snapshot(*sim_);  // t = 0, or the state restarted from, or the state now
}

Stop RunSession::advance(const Limits& limits, const std::function<bool()>& interrupted,
                         const std::function<void(const Simulation&)>& on_step) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const bool timed = std::isfinite(limits.wall_seconds);
  Simulation& sim = *sim_;
  ResultWriter* writer = writing() ? writer_.get() : nullptr;
  long done = 0;
  for (;;) {
    if (interrupted && interrupted()) return Stop::interrupted;
    if (limits.to_end && sim.finished()) return Stop::finished;
    if (done >= limits.max_steps || !(sim.time() < limits.until_time)) return Stop::limit;
    if (timed && done > 0 &&
        std::chrono::duration<double>(Clock::now() - start).count() >= limits.wall_seconds)
      return Stop::wall;
    try {
      sim.step();
    } catch (const Error& e) {
      if (!writer || e.code() != ExitCode::unstable) throw;
      // Keep the failing step (its diagnostics and state) for inspection.
      try {
        writer->record_step(sim);
        writer->snapshot(sim);
      } catch (const Error&) {  // the partial file keeps the earlier snapshots
      }
      throw Error(e.code(), std::string(e.what()) + "; " + partial_note());
    }
    ++done;
    if (writer) writer->step_done(sim);  // diagnostics every step, snapshots as configured
    if (on_step) on_step(sim);
  }
}

void RunSession::finish() {
  if (writing()) writer_->finish(*sim_);
}

void RunSession::abandon() {
  if (!writing()) return;
  writer_->last_snapshot(*sim_);  // with its restart state, to continue from
  writer_->close();
}

void RunSession::close_output() {
  if (writer_) writer_->close();
}

bool RunSession::writing() const {
  return writer_ && writer_->is_open();
}

std::string RunSession::partial_note() const {
  if (!writer_) return "";
  return fmt::format("the results up to step {} (t = {:.6g} s) are in {}; {} was not created",
                     sim_->steps_done(), sim_->time(), writer_->partial(), writer_->path());
}

}  // namespace erodem::io
