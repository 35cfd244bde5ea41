// erodem — the result file writer (HDF5, netCDF-4 / CF-1.8 compatible; results.hpp and
// docs/results.md): the file's sections (root attributes, coordinates and CRS, fields,
// diagnostics/, restart/, gauges/), the snapshots and per-step rows, and the finished file
// renamed into place; with the build's version strings and the run's provenance.
#include <fmt/format.h>
#include <hdf5.h>
#include <hdf5_hl.h>
#include <ogr_srs_api.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <exception>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>

#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/paths.hpp"
#include "erodem/io/results.hpp"
#include "erodem/parallel.hpp"
#include "erodem/process.hpp"
#include "erodem/schema.hpp"
#include "erodem/terrain_rows.hpp"
#include "h5.hpp"
#include "xdmf.hpp"

#ifndef ERODEM_VERSION
#define ERODEM_VERSION "unknown"
#endif
#ifndef ERODEM_GIT_DESCRIBE
#define ERODEM_GIT_DESCRIBE "unknown"
#endif

namespace erodem::io {

std::string build_version() {
  return ERODEM_VERSION;
}
std::string build_git_describe() {
  return ERODEM_GIT_DESCRIBE;
}

namespace {

namespace fs = std::filesystem;

/// The side of the fields' chunks (time, y, x) = (1, 512, 512), and the rows of a strip the
/// writer takes at a time: whole chunks, so that no compressed chunk is written twice.
constexpr hsize_t kChunkSide = 512;

/// Calls f(row0, row1) for the strips of kChunkSide rows of a grid of ny rows, in order,
/// until one returns false; whether all returned true.
template <class F>
bool for_strips(int ny, const F& f) {
  for (int row0 = 0; row0 < ny; row0 += static_cast<int>(kChunkSide))
    if (!f(row0, std::min(ny, row0 + static_cast<int>(kChunkSide)))) return false;
  return true;
}

/// The rows of strip [row0, row1) of field `id` that this process writes: in an MPI run that
/// writes one file together (collective_files()) the rows of its band, none where the band
/// misses the strip (no field is gathered to every rank); otherwise the whole strip. With
/// `nodata_nan`, NaN on the cells outside the DEM, set by the rank that owns them (a terrain
/// read by rows holds the mask of its band's rows alone).
OwnRows rows_to_write(const Simulation& sim, FieldId id, int row0, int row1, bool nodata_nan) {
  OwnRows r = sim.own_field_rows(id, row0, row1);
  if (nodata_nan) {
    const Terrain& terrain = sim.terrain();
    const std::size_t first = static_cast<std::size_t>(r.row0) * sim.grid().nx;
    for (std::size_t i = 0; i < r.values.size(); ++i)
      if (!terrain.active(first + i)) r.values[i] = std::nan("");
  }
  if (collective_files() || parallel::size() <= 1) return r;
  // MPI with one writer (serial HDF5): every rank's rows in rank order, which is row order
  std::vector<double> all = parallel::allgather(r.values);
  if (all.size() != static_cast<std::size_t>(row1 - row0) * sim.grid().nx)
    throw Error(ExitCode::internal, "result file: the ranks' rows of a strip do not tile it");
  return {row0, row1, std::move(all)};
}

std::string iso_utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

/// Units of the grid's x/y coordinates: "m" unless the CRS says otherwise.
std::string linear_units(const Georef& g) {
  if (g.is_geographic) return "degrees";
  if (g.crs_wkt.empty()) return "m";
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  std::string units = "m";
  if (OSRImportFromWkt(srs, std::array<char*, 1>{const_cast<char*>(g.crs_wkt.c_str())}.data()) ==
      OGRERR_NONE) {
    char* name = nullptr;
    const double factor = OSRGetLinearUnits(srs, &name);
    if (factor != 1.0 && name != nullptr && *name != '\0') units = name;
  }
  OSRDestroySpatialReference(srs);
  return units;
}

std::string geotransform_text(const std::array<double, 6>& t) {
  return fmt::format("{:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}", t[0], t[1], t[2], t[3],
                     t[4], t[5]);
}

}  // namespace

// ---- names --------------------------------------------------------------------------------

std::string partial_path(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() /
          fmt::format(".{}.{}-{}.partial", p.filename().string(), host_name(), getpid()))
      .string();
}

void remove_stale_partials(const std::string& path) {
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  const std::string prefix = "." + p.filename().string() + "." + host_name() + "-";
  const std::string suffix = ".partial";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string digits =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (digits.size() > 9 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == getpid() || pid <= 0 || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    fs::remove(it->path(), ignored);  // its process has ended: a run that stopped early
  }
}

std::string xdmf_path(const std::string& path) {
  return fs::path(path).replace_extension(".xmf").string();
}

Provenance Provenance::of(const Simulation& sim, const std::string& command_line) {
  Provenance p;
  p.command_line = command_line;
  p.config_toml = dump_toml(sim.params());
  p.backend = sim.backend().name();
  p.device = sim.backend().device();
  p.backend_reason = sim.backend().choice_reason();
  p.dem_path = sim.terrain().source;
  p.dem_sha256 = sim.terrain().source_sha256;
  return p;
}

// ---- ResultWriter ---------------------------------------------------------------------------

struct ResultWriter::Impl {
  std::string partial;  // for messages
  Grid grid;
  Params::Output output;
  std::string xname = "x", yname = "y";
  H5Id file, time;
  std::vector<std::pair<FieldInfo, H5Id>> fields;
  // diagnostics/
  H5Id diag_step;
  std::vector<H5Id> diag;
  std::vector<Diagnostics> pending;
  std::vector<std::int64_t> pending_steps;
  // gauges/
  std::vector<std::int64_t> gauge_cells;
  /// whether each gauge's cell is active (record_step's first call: terrain_rows.hpp, every
  /// rank's rows asked at once)
  std::vector<std::uint8_t> gauge_active;
  std::vector<FieldId> gauge_fields;  // depth, velocities, and the bed when it changes
  H5Id gauge_step, gauge_time;
  std::array<H5Id, 3> gauge;
  std::vector<double> pending_gauge_time;
  std::array<std::vector<double>, 3> pending_gauge;  // [series][row * n + gauge]
  std::vector<std::int64_t> pending_gauge_steps;
  // sections/: the [[section]] and [[outlet]] measures, one row per step
  std::size_t section_count = 0;
  H5Id section_step, section_time;
  std::array<H5Id, 4> section;
  std::vector<double> pending_section_time;
  std::array<std::vector<double>, 4> pending_section;  // [series][row * n + section]
  std::vector<std::int64_t> pending_section_steps;
  // restart/: the full state at every output.restart_every-th snapshot and the last
  // (output.restart_state); a state field no sweep of the step writes is stored once per
  // value (`once`): its rows in restart/NAME, and restart/NAME_row says which is whose
  bool restart = false;
  long restart_every = 1;
  bool restart_f64 = false;             // float64 runs keep their state in float64
  std::vector<H5Id> restart_fields;     // state_fields(), in order
  std::vector<bool> once;               // per state field: stored once per value
  std::vector<H5Id> restart_rows;       // per state field: its NAME_row dataset (once fields)
  std::vector<std::int32_t> row_count;  // per state field: rows stored (once)
  H5Id restart_time, restart_steps;
  std::vector<H5Id> restart_ledger;  // ledger_entries(), in order
  bool last_has_state = false;       // whether the last snapshot stored the state
  bool bed_changes = true;           // erosion or thermal on: the bed is read at every gauge sample
  std::vector<double> bed;           // the bed at the gauges, when it does not change

  H5Id create_group(const char* name) {
    H5Id gcpl = checked(H5Pcreate(H5P_GROUP_CREATE), partial, "group properties");
    H5Pset_link_creation_order(gcpl, kCreationOrder);
    H5Pset_attr_creation_order(gcpl, kCreationOrder);
    return checked(H5Gcreate2(file, name, H5P_DEFAULT, gcpl, H5P_DEFAULT), partial,
                   std::string("group ") + name);
  }

  /// A coordinate variable that is also the dimension scale `name`.
  H5Id coordinate(hid_t loc, const std::string& name, hid_t type, const void* values, hsize_t n,
                  bool unlimited) {
    const hsize_t dims = unlimited ? 0 : n, maxdims = unlimited ? H5S_UNLIMITED : n;
    H5Id ds = create_dataset(loc, name, type, {dims}, {maxdims},
                             unlimited ? std::vector<hsize_t>{512} : std::vector<hsize_t>{}, false,
                             nullptr, partial);
    if (!unlimited && n > 0) write_shared(ds, type, H5S_ALL, H5S_ALL, values, partial, name);
    checked(H5DSset_scale(ds, name.c_str()), partial, "dimension scale " + name);
    return ds;
  }

  /// A per-step series (step[, gauge]) in `loc`, its dimensions attached.
  H5Id series(hid_t loc, const std::string& name, hid_t step_scale, hid_t second_scale,
              hsize_t second, const char* units, const std::string& long_name) {
    std::vector<hsize_t> dims{0}, maxdims{H5S_UNLIMITED}, chunk{1024};
    if (second_scale >= 0) {
      dims.push_back(second);
      maxdims.push_back(second);
      chunk = {std::max<hsize_t>(1, 16384 / std::max<hsize_t>(second, 1)), second};
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    H5Id ds = create_dataset(loc, name, H5T_IEEE_F64LE, dims, maxdims, chunk, false, &nan, partial);
    checked(H5DSattach_scale(ds, step_scale, 0), partial, name + " dimensions");
    if (second_scale >= 0)
      checked(H5DSattach_scale(ds, second_scale, 1), partial, name + " dimensions");
    put_text(ds, "units", units, partial);
    put_text(ds, "long_name", long_name, partial);
    put_numbers(ds, "_FillValue", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &nan, 1, partial);
    return ds;
  }

  /// Writes the buffered rows of a (step, column) group: its steps, times and each series
  /// (`name(k)`: the dataset's name in `group`).
  template <std::size_t N, class Name>
  void flush_group(const char* group, hid_t step, hid_t times_ds, std::vector<std::int64_t>& steps,
                   std::vector<double>& times, std::array<H5Id, N>& series,
                   std::array<std::vector<double>, N>& rows, Name name) {
    const hsize_t n = times.size();
    if (n == 0) return;
    const std::string g = std::string(group) + "/";
    append_rows(step, H5T_NATIVE_INT64, n, steps.data(), partial, g + "step");
    append_rows(times_ds, H5T_NATIVE_DOUBLE, n, times.data(), partial, g + "time");
    for (std::size_t k = 0; k < N; ++k) {
      append_rows(series[k], H5T_NATIVE_DOUBLE, n, rows[k].data(), partial, g + name(k));
      rows[k].clear();
    }
    times.clear();
    steps.clear();
  }

  /// Writes the buffered diagnostics, gauge and section rows.
  void flush_pending() {
    const hsize_t rows = pending.size();
    if (rows > 0) {
      append_rows(diag_step, H5T_NATIVE_INT64, rows, pending_steps.data(), partial,
                  "diagnostics/step");
      std::vector<double> column(rows);
      for (std::size_t k = 0; k < diag.size(); ++k) {
        const auto& s = diagnostics_series()[k];
        for (std::size_t r = 0; r < rows; ++r) column[r] = pending[r].*s.member;
        append_rows(diag[k], H5T_NATIVE_DOUBLE, rows, column.data(), partial,
                    std::string("diagnostics/") + s.name);
      }
      pending.clear();
      pending_steps.clear();
    }
    flush_group("gauges", gauge_step, gauge_time, pending_gauge_steps, pending_gauge_time, gauge,
                pending_gauge, [](std::size_t k) { return kGaugeSeries[k]; });
    flush_group("sections", section_step, section_time, pending_section_steps, pending_section_time,
                section, pending_section, [](std::size_t k) { return kSectionSeries[k].name; });
  }

  void close() {
    for (auto& f : fields) f.second.reset();
    for (auto& d : diag) d.reset();
    for (auto& g : gauge) g.reset();
    for (auto& g : section) g.reset();
    section_step.reset();
    section_time.reset();
    for (auto& d : restart_fields) d.reset();
    for (auto& d : restart_rows) d.reset();
    for (auto& d : restart_ledger) d.reset();
    restart_steps.reset();
    restart_time.reset();
    diag_step.reset();
    gauge_step.reset();
    gauge_time.reset();
    time.reset();
    file.reset();
  }
};

ResultWriter::ResultWriter(const std::string& path, const Simulation& sim,
                           const std::string& command_line, bool overwrite)
    : ResultWriter(path, sim.grid(), sim.params(), Provenance::of(sim, command_line), overwrite) {}

ResultWriter::ResultWriter(const std::string& path, const Grid& grid, const Params& params,
                           const Provenance& prov, bool overwrite)
    : path_(path), partial_(root_text(partial_path(path))), overwrite_(overwrite) {
  QuietH5 quiet;
  check_output_path(path, overwrite);  // folder exists and is writable, no file in the way
  seen_ = file_identity(path);         // what --overwrite may replace at finish()
  if (grid.nx <= 0 || grid.ny <= 0)
    throw Error(ExitCode::internal, path + ": result file for an empty grid");

  auto impl = std::make_unique<Impl>();
  Impl& m = *impl;
  m.partial = partial_;
  m.grid = grid;
  m.output = params.output;
  m.bed_changes = bed_changes(params);  // a sweep of the step writes the bed (process.hpp)
  m.restart = params.output.restart_state;
  m.restart_every = params.output.restart_every;
  m.restart_f64 = params.numerics.precision == Precision::float64;
  for (const auto& name : m.output.fields) m.fields.emplace_back(field_info(name), H5Id());
  // Gauges must lie on the grid.
  for (std::size_t i = 0; i < m.output.gauges.size(); ++i) {
    const auto& g = m.output.gauges[i];
    int col = 0, row = 0;
    if (!grid.locate(g[0], g[1], col, row))
      throw config_error(
          fmt::format("output.gauges[{}]", i),
          fmt::format("({:.10g}, {:.10g}) is outside the grid (x {:.10g} .. {:.10g}, y {:.10g} "
                      ".. {:.10g})",
                      g[0], g[1], grid.cell_center(0, 0)[0] - 0.5 * grid.georef.transform[1],
                      grid.cell_center(grid.nx - 1, 0)[0] + 0.5 * grid.georef.transform[1],
                      grid.cell_center(0, grid.ny - 1)[1] + 0.5 * grid.georef.transform[5],
                      grid.cell_center(0, 0)[1] - 0.5 * grid.georef.transform[5]));
    m.gauge_cells.push_back(static_cast<std::int64_t>(row) * grid.nx + col);
  }
  m.gauge_fields = {FieldId::water_depth, FieldId::velocity_x, FieldId::velocity_y};
  if (m.bed_changes) m.gauge_fields.push_back(FieldId::bed);

  // The file, tracking creation order like netCDF-4.
  H5Id fcpl = checked(H5Pcreate(H5P_FILE_CREATE), partial_, "file properties");
  H5Pset_link_creation_order(fcpl, kCreationOrder);
  H5Pset_attr_creation_order(fcpl, kCreationOrder);
  // (MPI with parallel HDF5: every rank opens rank 0's partial file, root_text above)
  const H5Id fapl = file_access(partial_);
  m.file = H5Id(H5Fcreate(partial_.c_str(), H5F_ACC_TRUNC, fcpl, fapl));
  if (!m.file.valid())
    throw Error(ExitCode::cant_create, partial_ + ": cannot create" + h5_open_reason(partial_));
  if (parallel::rank() == 0) remove_stale_partials(path);

  // Root attributes.
  const std::pair<const char*, std::string> root_attrs[] = {
      {"Conventions", "CF-1.8"},
      {"title", "erodem run"},
      {"source", "erodem " + prov.erodem_version},
      {"erodem_version", prov.erodem_version},
      {"git_describe", prov.git_describe},
      {"created", iso_utc_now()},
      {"command_line", prov.command_line},
      {"config_toml", prov.config_toml},
      {"backend", prov.backend},
      {"backend_reason", prov.backend_reason},
      {"device", prov.device},
      {"dem_path", prov.dem_path},
      {"dem_sha256", prov.dem_sha256},
  };
  for (const auto& [name, value] : root_attrs) put_text(m.file, name, value, partial_);
  if (!prov.restart_from.empty()) put_text(m.file, "restart_from", prov.restart_from, partial_);

  // Dimensions and coordinates: time (unlimited), y, x.
  const auto& geo = grid.georef;
  if (geo.is_geographic) {
    m.xname = "lon";
    m.yname = "lat";
  }
  m.time = m.coordinate(m.file, "time", H5T_IEEE_F64LE, nullptr, 0, true);
  put_text(m.time, "units", "s", partial_);
  put_text(m.time, "long_name", "time since the start of the run", partial_);
  put_text(m.time, "axis", "T", partial_);
  std::vector<double> xs(static_cast<std::size_t>(grid.nx)), ys(static_cast<std::size_t>(grid.ny));
  for (int c = 0; c < grid.nx; ++c) xs[c] = grid.cell_center(c, 0)[0];
  for (int r = 0; r < grid.ny; ++r) ys[r] = grid.cell_center(0, r)[1];
  H5Id y = m.coordinate(m.file, m.yname, H5T_IEEE_F64LE, ys.data(), ys.size(), false);
  H5Id x = m.coordinate(m.file, m.xname, H5T_IEEE_F64LE, xs.data(), xs.size(), false);
  const std::string units = linear_units(geo);
  if (geo.is_geographic) {
    put_text(y, "units", "degrees_north", partial_);
    put_text(y, "standard_name", "latitude", partial_);
    put_text(y, "long_name", "latitude of cell centre", partial_);
    put_text(x, "units", "degrees_east", partial_);
    put_text(x, "standard_name", "longitude", partial_);
    put_text(x, "long_name", "longitude of cell centre", partial_);
  } else {
    put_text(y, "units", units, partial_);
    put_text(y, "standard_name", "projection_y_coordinate", partial_);
    put_text(y, "long_name", "y coordinate of cell centre", partial_);
    put_text(x, "units", units, partial_);
    put_text(x, "standard_name", "projection_x_coordinate", partial_);
    put_text(x, "long_name", "x coordinate of cell centre", partial_);
  }
  put_text(y, "axis", "Y", partial_);
  put_text(x, "axis", "X", partial_);
  // Cell sizes and areas of each row (m, m^2): exact for geographic grids too.
  {
    const std::pair<const char*, const std::vector<double>*> rows[] = {
        {"cell_dx", &grid.dx}, {"cell_dy", &grid.dy}, {"cell_area", &grid.area}};
    const char* row_long[] = {"east-west cell size of the row", "north-south cell size of the row",
                              "cell area of the row"};
    for (std::size_t k = 0; k < 3; ++k) {
      const auto& [name, values] = rows[k];
      if (values->size() != static_cast<std::size_t>(grid.ny)) continue;
      H5Id ds = create_dataset(m.file, name, H5T_IEEE_F64LE, {ys.size()}, {ys.size()}, {}, false,
                               nullptr, partial_);
      write_shared(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, values->data(), partial_, name);
      checked(H5DSattach_scale(ds, y, 0), partial_, std::string(name) + " dimensions");
      put_text(ds, "units", k == 2 ? "m2" : "m", partial_);
      put_text(ds, "long_name", row_long[k], partial_);
    }
  }

  // The grid mapping.
  {
    const std::int32_t zero = 0;
    H5Id crs = create_dataset(m.file, "crs", H5T_STD_I32LE, {}, {}, {}, false, nullptr, partial_);
    write_shared(crs, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, &zero, partial_, "crs");
    put_text(crs, "long_name", "coordinate reference system", partial_);
    if (!geo.crs_wkt.empty()) {
      put_text(crs, "crs_wkt", geo.crs_wkt, partial_);
      put_text(crs, "spatial_ref", geo.crs_wkt, partial_);
    } else {
      put_text(crs, "comment",
               "the CRS of the DEM is unknown; coordinates are in metres from the grid origin",
               partial_);
    }
    put_text(crs, "GeoTransform", geotransform_text(geo.transform), partial_);
  }

  // Fields (time, y, x): float32, one time slice per chunk, shuffle + deflate.
  const float fnan = std::numeric_limits<float>::quiet_NaN();
  const hsize_t ny = grid.ny, nx = grid.nx;
  for (auto& [info, ds] : m.fields) {
    ds = create_dataset(m.file, info.name, H5T_IEEE_F32LE, {0, ny, nx}, {H5S_UNLIMITED, ny, nx},
                        {1, std::min<hsize_t>(ny, kChunkSide), std::min<hsize_t>(nx, kChunkSide)},
                        true, &fnan, partial_);
    checked(H5DSattach_scale(ds, m.time, 0), partial_, std::string(info.name) + " dimensions");
    checked(H5DSattach_scale(ds, y, 1), partial_, std::string(info.name) + " dimensions");
    checked(H5DSattach_scale(ds, x, 2), partial_, std::string(info.name) + " dimensions");
    put_text(ds, "units", info.units, partial_);
    put_text(ds, "long_name", info.long_name, partial_);
    put_text(ds, "grid_mapping", "crs", partial_);
    put_numbers(ds, "_FillValue", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, &fnan, 1, partial_);
  }

  // diagnostics/: one row per step.
  {
    H5Id group = m.create_group("diagnostics");
    put_text(group, "comment", "one row per simulation step, at the end of the step", partial_);
    m.diag_step = m.coordinate(group, "step", H5T_STD_I64LE, nullptr, 0, true);
    put_text(m.diag_step, "long_name", "number of steps done", partial_);
    for (const auto& s : diagnostics_series())
      m.diag.push_back(m.series(group, s.name, m.diag_step, -1, 0, s.units, s.long_name));
  }

  // restart/: every state field in the precision of the run (so a restart is exact), the
  // step count and the ledger, at every output.restart_every-th snapshot and the last, on
  // their own time axis restart/time; a field no sweep of the step writes, once per value.
  if (m.restart) {
    H5Id group = m.create_group("restart");
    put_text(group, "comment",
             "the full state at the times restart/time (output.restart_every), for erodem run "
             "--restart FILE:TIME; not masked: inactive cells hold their internal values; a "
             "field with a NAME_row dataset is stored once per value, NAME_row giving the row "
             "of NAME at each time",
             partial_);
    m.restart_time = m.coordinate(group, "time", H5T_IEEE_F64LE, nullptr, 0, true);
    put_text(m.restart_time, "units", "s", partial_);
    put_text(m.restart_time, "long_name", "times of the stored states", partial_);
    const hid_t type = m.restart_f64 ? H5T_IEEE_F64LE : H5T_IEEE_F32LE;
    auto per_state = [&](const std::string& name, hid_t t, const char* unit,
                         const std::string& long_name) {
      H5Id ds =
          create_dataset(group, name, t, {0}, {H5S_UNLIMITED}, {512}, false, nullptr, partial_);
      checked(H5DSattach_scale(ds, m.restart_time, 0), partial_, "restart/" + name);
      put_text(ds, "units", unit, partial_);
      put_text(ds, "long_name", long_name, partial_);
      return ds;
    };
    for (FieldId id : state_fields()) {
      const auto& info = field_info(id);
      const bool once = !step_writes(params, info.name);
      H5Id ds =
          create_dataset(group, info.name, type, {0, ny, nx}, {H5S_UNLIMITED, ny, nx},
                         {1, std::min<hsize_t>(ny, kChunkSide), std::min<hsize_t>(nx, kChunkSide)},
                         true, nullptr, partial_);
      if (!once)
        checked(H5DSattach_scale(ds, m.restart_time, 0), partial_,
                std::string("restart/") + info.name);
      checked(H5DSattach_scale(ds, y, 1), partial_, std::string("restart/") + info.name);
      checked(H5DSattach_scale(ds, x, 2), partial_, std::string("restart/") + info.name);
      put_text(ds, "units", info.units, partial_);
      put_text(ds, "long_name", info.long_name, partial_);
      m.restart_fields.push_back(std::move(ds));
      m.once.push_back(once);
      m.restart_rows.push_back(once ? per_state(std::string(info.name) + "_row", H5T_STD_I32LE, "1",
                                                std::string("row of restart/") + info.name +
                                                    " holding the state at each time")
                                    : H5Id());
    }
    m.row_count.assign(m.once.size(), 0);
    m.restart_steps = per_state("steps", H5T_STD_I64LE, "1", "steps done");
    for (const auto& e : ledger_entries())
      m.restart_ledger.push_back(per_state(std::string("ledger_") + e.name, H5T_IEEE_F64LE, "m3",
                                           std::string("ledger entry ") + e.name));
  }

  // gauges/: one row per step, one column per gauge.
  if (!m.gauge_cells.empty()) {
    H5Id group = m.create_group("gauges");
    put_text(group, "comment",
             "values of the cells containing the gauges (output.gauges), one row per step",
             partial_);
    const hsize_t n = m.gauge_cells.size();
    std::vector<std::int32_t> ids(n);
    std::vector<double> gx(n), gy(n);
    for (std::size_t i = 0; i < n; ++i) {
      ids[i] = static_cast<std::int32_t>(i);
      gx[i] = m.output.gauges[i][0];
      gy[i] = m.output.gauges[i][1];
    }
    H5Id gauge = m.coordinate(group, "gauge", H5T_STD_I32LE, ids.data(), n, false);
    put_text(gauge, "long_name", "gauge index in output.gauges", partial_);
    for (const auto& [name, values] : {std::pair{"x", &gx}, std::pair{"y", &gy}}) {
      H5Id ds = create_dataset(group, name, H5T_IEEE_F64LE, {n}, {n}, {}, false, nullptr, partial_);
      write_shared(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, values->data(), partial_,
                   std::string("gauges/") + name);
      checked(H5DSattach_scale(ds, gauge, 0), partial_, std::string("gauges/") + name);
      const bool is_x = std::string(name) == "x";
      put_text(ds, "units", geo.is_geographic ? (is_x ? "degrees_east" : "degrees_north") : units,
               partial_);
      put_text(ds, "long_name", std::string("gauge ") + name + " coordinate", partial_);
    }
    m.gauge_step = m.coordinate(group, "step", H5T_STD_I64LE, nullptr, 0, true);
    put_text(m.gauge_step, "long_name", "number of steps done", partial_);
    m.gauge_time = m.series(group, "time", m.gauge_step, -1, 0, "s",
                            "time since the start of the run, at the end of the step");
    const char* gunits[] = {"m", "m", "m s-1"};
    const char* glong[] = {"water depth at the gauge", "water surface elevation at the gauge",
                           "flow speed at the gauge"};
    for (std::size_t k = 0; k < m.gauge.size(); ++k)
      m.gauge[k] = m.series(group, kGaugeSeries[k], m.gauge_step, gauge, n, gunits[k], glong[k]);
  }
  // sections/: one row per step, one column per section or outlet (sections.hpp).
  m.section_count = params.section.size() + params.outlet.size();
  if (m.section_count > 0) {
    H5Id group = m.create_group("sections");
    put_text(group, "comment",
             "discharge and sediment flux through the cross-sections ([[section]]: positive "
             "from the left to the right of the line, walking from its first vertex) and "
             "outlets ([[outlet]]: positive out of the grid), one row per step",
             partial_);
    const hsize_t n = m.section_count;
    std::vector<std::int32_t> ids(n), outlet(n);
    std::string names;
    for (std::size_t i = 0; i < n; ++i) {
      ids[i] = static_cast<std::int32_t>(i);
      outlet[i] = i >= params.section.size();
      names += (i ? "," : "") +
               (outlet[i] ? params.outlet[i - params.section.size()].name : params.section[i].name);
    }
    // the names, comma-separated (a name has no comma: schema), in the section order
    put_text(group, "section_names", names, partial_);
    H5Id sec = m.coordinate(group, "section", H5T_STD_I32LE, ids.data(), n, false);
    put_text(sec, "long_name", "section index: the [[section]] tables, then the [[outlet]] tables",
             partial_);
    H5Id is_outlet =
        create_dataset(group, "outlet", H5T_STD_I32LE, {n}, {n}, {}, false, nullptr, partial_);
    write_shared(is_outlet, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, outlet.data(), partial_,
                 "sections/outlet");
    checked(H5DSattach_scale(is_outlet, sec, 0), partial_, "sections/outlet");
    put_text(is_outlet, "units", "1", partial_);
    put_text(is_outlet, "long_name", "1 for an [[outlet]], 0 for a [[section]]", partial_);
    m.section_step = m.coordinate(group, "step", H5T_STD_I64LE, nullptr, 0, true);
    put_text(m.section_step, "long_name", "number of steps done", partial_);
    m.section_time = m.series(group, "time", m.section_step, -1, 0, "s",
                              "time since the start of the run, at the end of the step");
    for (std::size_t k = 0; k < m.section.size(); ++k)
      m.section[k] = m.series(group, kSectionSeries[k].name, m.section_step, sec, n,
                              kSectionSeries[k].units, kSectionSeries[k].long_name);
  }
  checked(H5Fflush(m.file, H5F_SCOPE_GLOBAL), partial_, "(flushing)");
  impl_ = std::move(impl);
}

ResultWriter::~ResultWriter() {
  close();
}

void ResultWriter::close() {
  if (!impl_) return;
  if (collective_files() && std::uncaught_exceptions() > 0) {
    // MPI, one file: closing is collective, and the other ranks may be waiting elsewhere (an
    // error this rank alone met): the handles are left open for MPI_Abort (main.cpp), which
    // ends every rank; the partial file holds what its last flush wrote (every snapshot's).
    static_cast<void>(impl_.release());
    return;
  }
  QuietH5 quiet;
  try {
    impl_->flush_pending();
  } catch (...) {  // closing reports nothing; the file keeps what it had
  }
  impl_->close();
  impl_.reset();
}

void ResultWriter::store_state(const Simulation& sim) {
  Impl& m = *impl_;
  // One field at a time (Simulation::restart_point() would hold every state field in double
  // at once: 8 bytes per cell for each of them, the run's peak at every snapshot).
  // A float32 state is written from the doubles: HDF5 rounds them to the dataset's floats
  // (as static_cast<float>) a strip at a time, so no float copy of the field is held.
  const int ny = m.grid.ny;
  for (std::size_t k = 0; k < state_fields().size(); ++k) {
    const FieldId id = state_fields()[k];
    const std::string name = std::string("restart/") + field_info(id).name;
    const hid_t ds = m.restart_fields[k];
    if (m.once[k]) {  // a new row only when the values differ from the last one stored
      bool same = false;
      if (m.row_count[k] > 0) {  // compared with that row as the file holds it, strip by strip
        // (in an MPI run each rank its own rows, read independently, then whether they are the
        // same on every rank: every rank decides alike)
        const hsize_t last_row = static_cast<hsize_t>(m.row_count[k] - 1);
        same = !parallel::any(!for_strips(ny, [&](int row0, int row1) {
          const OwnRows own = sim.own_field_rows(id, row0, row1);
          const std::vector<double>& v = own.values;
          const hsize_t rows = static_cast<hsize_t>(own.row1 - own.row0);
          if (rows == 0) return true;
          if (m.restart_f64) {
            std::vector<double> last(v.size());
            read_strip(ds, H5T_NATIVE_DOUBLE, last_row, own.row0, rows, last.data(), partial_,
                       name);
            return std::memcmp(last.data(), v.data(), v.size() * sizeof(double)) == 0;
          }
          std::vector<float> last(v.size());
          read_strip(ds, H5T_NATIVE_FLOAT, last_row, own.row0, rows, last.data(), partial_, name);
          for (std::size_t i = 0; i < v.size(); ++i) {
            const float f = static_cast<float>(v[i]);
            if (std::memcmp(&last[i], &f, sizeof(float)) != 0) return false;
          }
          return true;
        }));
      }
      const std::int32_t index = same ? m.row_count[k] - 1 : m.row_count[k];
      append_rows(m.restart_rows[k], H5T_NATIVE_INT32, 1, &index, partial_, name + "_row");
      if (same) continue;
      ++m.row_count[k];
    }
    const hsize_t index = grow_row(ds, partial_, name);
    for_strips(ny, [&](int row0, int row1) {
      const OwnRows r = rows_to_write(sim, id, row0, row1, false);
      write_strip(ds, H5T_NATIVE_DOUBLE, index, r.row0, r.row1 - r.row0, r.values.data(), partial_,
                  name);
      return true;
    });
  }
  const std::int64_t steps = sim.steps_done();
  append_rows(m.restart_steps, H5T_NATIVE_INT64, 1, &steps, partial_, "restart/steps");
  for (std::size_t k = 0; k < ledger_entries().size(); ++k) {
    const double v = sim.ledger().*ledger_entries()[k].member;
    append_rows(m.restart_ledger[k], H5T_NATIVE_DOUBLE, 1, &v, partial_,
                std::string("restart/ledger_") + ledger_entries()[k].name);
  }
  // The time last: a file cut short lists only the complete states.
  const double t = sim.time();
  append_rows(m.restart_time, H5T_NATIVE_DOUBLE, 1, &t, partial_, "restart/time");
  ++states_;
}

void ResultWriter::snapshot(const Simulation& sim) {
  take_snapshot(sim, false);
}

void ResultWriter::last_snapshot(const Simulation& sim) {
  if (!impl_) return;
  if (last_snapshot_step_ != sim.steps_done()) return take_snapshot(sim, true);
  if (impl_->restart && !impl_->last_has_state) {  // the state of the last snapshot
    QuietH5 quiet;
    store_state(sim);
    impl_->last_has_state = true;
    checked(H5Fflush(impl_->file, H5F_SCOPE_GLOBAL), partial_, "(flushing)");
  }
}

void ResultWriter::take_snapshot(const Simulation& sim, bool last) {
  if (!impl_) throw Error(ExitCode::internal, path_ + ": snapshot after finish()");
  QuietH5 quiet;
  Impl& m = *impl_;
  const Grid& g = sim.grid();
  if (g.nx != m.grid.nx || g.ny != m.grid.ny)
    throw Error(ExitCode::internal, path_ + ": snapshot of a simulation on another grid");
  for (auto& [info, ds] : m.fields) {
    // NaN on the cells outside the DEM; HDF5 rounds the doubles to the dataset's floats
    const hsize_t index = grow_row(ds, partial_, info.name);
    for_strips(g.ny, [&](int row0, int row1) {
      const OwnRows r = rows_to_write(sim, info.id, row0, row1, true);
      write_strip(ds, H5T_NATIVE_DOUBLE, index, r.row0, r.row1 - r.row0, r.values.data(), partial_,
                  info.name);
      return true;
    });
  }
  const bool state = m.restart && (last || times_.size() % m.restart_every == 0);
  if (state) store_state(sim);
  // The time last: a file cut short mid-snapshot lists only the complete snapshots.
  const double t = sim.time();
  append_rows(m.time, H5T_NATIVE_DOUBLE, 1, &t, partial_, "time");
  times_.push_back(t);
  last_snapshot_step_ = sim.steps_done();
  m.last_has_state = state;
  m.flush_pending();
  checked(H5Fflush(m.file, H5F_SCOPE_GLOBAL), partial_, "(flushing)");
}

void ResultWriter::record_step(const Simulation& sim) {
  if (!impl_) throw Error(ExitCode::internal, path_ + ": record_step after finish()");
  Impl& m = *impl_;
  m.pending.push_back(sim.diagnostics());
  m.pending_steps.push_back(sim.steps_done());
  if (m.section_count > 0 && sim.sections().size() == m.section_count) {
    m.pending_section_time.push_back(sim.time());
    m.pending_section_steps.push_back(sim.steps_done());
    for (const SectionState& st : sim.sections())
      for (std::size_t k = 0; k < m.section.size(); ++k)
        m.pending_section[k].push_back(st.*kSectionSeries[k].member);
  }
  if (m.gauge_cells.empty()) return;
  // The gauge fields at the gauge cells: the step's probes where the simulation took them for
  // these gauges (RunSession registers them: Simulation::set_probes), else sampled now; no
  // whole field is read. Both give the values field(id)[cell] would.
  const std::size_t n = m.gauge_cells.size();
  const std::vector<double>* probes = sim.probes();
  std::vector<double> sampled;
  if (!probes || sim.probe_cells() != m.gauge_cells || sim.probe_fields() != m.gauge_fields) {
    for (const FieldId id : m.gauge_fields) {
      const auto v = sim.sample(m.gauge_cells, id);
      sampled.insert(sampled.end(), v.begin(), v.end());
    }
    probes = &sampled;
  }
  const double* depth = probes->data();  // gauge_fields' order
  const double* vx = depth + n;
  const double* vy = vx + n;
  if (m.bed_changes)
    m.bed.assign(vy + n, vy + 2 * n);
  else if (m.bed.empty())
    m.bed = sim.sample(m.gauge_cells, FieldId::bed);
  const auto& bed = m.bed;
  m.pending_gauge_time.push_back(sim.time());
  m.pending_gauge_steps.push_back(sim.steps_done());
  if (m.gauge_active.size() != n) m.gauge_active = cells_active(sim.terrain(), m.gauge_cells);
  for (std::size_t j = 0; j < n; ++j) {
    const bool on = m.gauge_active[j] != 0;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    m.pending_gauge[0].push_back(on ? depth[j] : nan);
    m.pending_gauge[1].push_back(on ? bed[j] + depth[j] : nan);
    m.pending_gauge[2].push_back(on ? std::hypot(vx[j], vy[j]) : nan);
  }
}

const std::vector<std::int64_t>& ResultWriter::gauge_cells() const {
  static const std::vector<std::int64_t> none;
  return impl_ ? impl_->gauge_cells : none;
}

const std::vector<FieldId>& ResultWriter::gauge_fields() const {
  static const std::vector<FieldId> none;
  return impl_ ? impl_->gauge_fields : none;
}

bool ResultWriter::snapshot_due(const Simulation& sim) const {
  if (times_.empty()) return true;
  if (sim.steps_done() == last_snapshot_step_) return false;
  if (!impl_) return false;
  const auto& out = impl_->output;
  if (out.interval > 0) {
    const double eps = 1e-9 * out.interval;
    return std::floor((sim.time() + eps) / out.interval) >
           std::floor((times_.back() + eps) / out.interval);
  }
  return out.every > 0 && sim.steps_done() % out.every == 0;
}

void ResultWriter::step_done(const Simulation& sim) {
  record_step(sim);
  if (snapshot_due(sim)) snapshot(sim);
}

void ResultWriter::finish(const Simulation& sim) {
  last_snapshot(sim);
  finish();
}

void ResultWriter::finish() {
  if (!impl_) return;
  QuietH5 quiet;
  Impl& m = *impl_;
  m.flush_pending();
  const Grid grid = m.grid;
  const std::string xname = m.xname, yname = m.yname;
  std::vector<FieldInfo> infos;
  for (const auto& f : m.fields) infos.push_back(f.first);
  m.close();
  impl_.reset();

  if (parallel::rank() != 0) return;  // MPI: rank 0 publishes (the file is closed on all ranks)
  publish();
  write_xdmf(path_, grid, xname, yname, times_, infos);
}

void ResultWriter::publish(bool force_link) const {
  // Never over a file another process put at `path` during the run: without overwrite
  // nothing may be there, with it only the file seen at the start (or nothing).
  const FileIdentity now = file_identity(path_);
  const std::string kept = "; this run's results are in " + partial_;
  if (overwrite_ && now.exists) {
    if (now != seen_)
      throw Error(ExitCode::cant_create,
                  path_ +
                      (seen_.exists ? ": replaced by another process during the run"
                                    : ": created by another process during the run") +
                      "; not overwritten" + kept);
    std::error_code ec;
    fs::rename(partial_, path_, ec);
    if (ec)
      throw Error(ExitCode::io,
                  path_ + ": cannot rename " + partial_ + " into place: " + ec.message() + kept);
    return;
  }
  const int err = rename_no_replace(partial_, path_, force_link);
  if (err == EEXIST)
    throw Error(ExitCode::cant_create,
                path_ + ": exists (created by another process during the run); not overwritten" +
                    (overwrite_ ? "" : " (give --overwrite)") + kept);
  if (err != 0)
    throw Error(ExitCode::io, path_ + ": cannot rename " + partial_ +
                                  " into place: " + std::strerror(err) + kept);
}

}  // namespace erodem::io
