// `erodem export RUN.h5 --field F [--time T] OUT.tif`: one stored field at one stored time
// as a GeoTIFF with the run's georeferencing.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/results.hpp"

namespace erodem::cli {

namespace {

struct ExportOptions {
  std::string run, field, output;
  double time = NAN;  // NaN: the last snapshot
  bool overwrite = false;
};

std::string list_times(const std::vector<double>& times) {
  std::string s;
  for (std::size_t k = 0; k < times.size() && k < 12; ++k)
    s += (k ? ", " : "") + fmt::format("{:g}", times[k]);
  if (times.size() > 12) s += fmt::format(", ... ({} in all)", times.size());
  return s;
}

int export_field(const ExportOptions& o) {
  io::ResultReader reader(o.run);
  const auto& times = reader.times();
  if (times.empty()) throw Error(ExitCode::data, o.run + ": holds no snapshot");
  std::size_t index = times.size() - 1;
  if (!std::isnan(o.time)) {
    index = reader.nearest_time_index(o.time);
    const double tol = 1e-9 * std::max(1.0, std::abs(o.time));
    if (!(std::abs(times[index] - o.time) <= tol))
      throw Error(ExitCode::data, fmt::format("{}: no snapshot at t = {:g} s (stored: {} s)", o.run,
                                              o.time, list_times(times)));
  }
  bool known = false;
  std::string names;
  for (const auto& f : reader.fields()) {
    known = known || f == o.field;
    names += (names.empty() ? "" : ", ") + f;
  }
  if (!known)
    throw Error(ExitCode::data,
                fmt::format("{}: no field '{}' (stored: {})", o.run, o.field, names));
  check_output_path(o.output, o.overwrite);
  const auto values = reader.read_index(o.field, index);
  io::write_geotiff(o.output, reader.grid(), values,
                    fmt::format("{} at t = {:g} s from {}", o.field, times[index], o.run));
  std::printf("wrote %s: %s at t = %g s (%d x %d)\n", o.output.c_str(), o.field.c_str(),
              times[index], reader.grid().nx, reader.grid().ny);
  return 0;
}

}  // namespace

Action add_export(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  auto* sub = app.add_subcommand("export", "Write one field at one stored time as a GeoTIFF");
  sub->add_option("run", o->run, "Result file (.h5)")->required();
  sub->add_option("--field", o->field, "Field name (e.g. water_depth)")->required();
  sub->add_option("--time", o->time, "Stored time (s); default: the last snapshot");
  sub->add_flag("--overwrite", o->overwrite, "Replace an existing file");
  sub->add_option("output", o->output, "Output GeoTIFF")->required();
  return [o] { return export_field(*o); };
}

}  // namespace erodem::cli
