// `erodem compare A B`: per field, the relative L2 and the largest absolute difference
// between two run outputs at their matching snapshot times; exit 1 when a field differs by
// more than the tolerance.
//
// A run output is a result file (`run.h5`, read with io::ResultReader), the set of GeoTIFFs
// that `erodem run` wrote before the HDF5 writer (`out.h5` -> out_bed.tif, ...), or a single
// GeoTIFF. A GeoTIFF holds one state: it is compared with the last snapshot of a result file.
#include <cpl_conv.h>
#include <cpl_error.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/results.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace {

namespace fs = std::filesystem;

struct CompareOptions {
  std::string a, b;
  double tol = 1e-5;
  bool json = false;
  std::string fields;
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

bool is_geotiff_name(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".tif" || ext == ".tiff";
}

/// The GeoTIFF of field `name` of a run whose output is `path` (as cmd_run.cpp names it).
std::string field_file(const std::string& path, const std::string& name) {
  fs::path p(path);
  p.replace_extension();
  return p.string() + "_" + name + ".tif";
}

/// One side of the comparison: a result file, or field name -> GeoTIFF. A single GeoTIFF
/// has one entry, named after the field its file name ends with ("out_water_depth.tif"),
/// else "".
struct Output {
  std::string path;
  bool single = false;
  std::shared_ptr<io::ResultReader> h5;  ///< set for a result file
  std::map<std::string, std::string> files;

  bool has(const std::string& field) const {
    if (h5) {
      const auto f = h5->fields();
      return std::find(f.begin(), f.end(), field) != f.end();
    }
    return files.count(field) != 0;
  }
  std::vector<std::string> fields() const {
    if (h5) return h5->fields();
    std::vector<std::string> out;
    for (const auto& f : field_table())
      if (files.count(f.name)) out.push_back(f.name);
    return out;
  }
  std::string missing(const std::string& field) const {
    return h5 ? fmt::format("{}: field '{}' missing: the file holds {}", path, field,
                            fmt::join(h5->fields(), ", "))
              : fmt::format("{}: field '{}' missing: no file {}", path, field,
                            field_file(path, field));
  }
};

Output resolve(const std::string& path) {
  Output o;
  o.path = path;
  std::error_code ec;
  if (is_geotiff_name(path)) {
    if (!fs::exists(path, ec)) throw Error(ExitCode::no_input, path + ": no such file");
    o.single = true;
    const std::string stem = fs::path(path).stem().string();
    std::string name;
    for (const auto& f : field_table()) {
      const std::string suffix = std::string("_") + f.name;
      if (stem.size() > suffix.size() &&
          stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0 &&
          std::string(f.name).size() > name.size())
        name = f.name;
    }
    o.files[name] = path;
    return o;
  }
  if (fs::exists(path, ec)) {
    o.h5 = std::make_shared<io::ResultReader>(path);  // not a result file -> Error(data)
    return o;
  }
  for (const auto& f : field_table()) {
    const std::string file = field_file(path, f.name);
    if (fs::exists(file, ec)) o.files[f.name] = file;
  }
  if (o.files.empty())
    throw Error(ExitCode::no_input, fmt::format("{}: no such file (nor GeoTIFF fields {})", path,
                                                field_file(path, "<field>")));
  return o;
}

/// Band 1 of a raster, nodata and non-finite values as NaN, with its georeferencing.
struct Raster {
  std::string path;
  int nx = 0, ny = 0;
  bool has_transform = false;
  double transform[6] = {0, 1, 0, 0, 0, 1};
  std::string crs_wkt;
  std::vector<double> values;
};

/// Closes a GDAL dataset on every path.
struct DatasetCloser {
  void operator()(void* ds) const {
    if (ds) GDALClose(ds);
  }
};

Raster read_raster(const std::string& path) {
  static const bool registered = [] {
    GDALAllRegister();
    return true;
  }();
  (void)registered;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(ExitCode::no_input, path + ": no such file");
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
  std::unique_ptr<void, DatasetCloser> ds(
      GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  const std::string gdal_msg = CPLGetLastErrorMsg();
  CPLPopErrorHandler();
  if (!ds)
    throw Error(ExitCode::data, fmt::format("{}: not a raster GDAL can read{}", path,
                                            gdal_msg.empty() ? "" : " (" + gdal_msg + ")"));
  Raster r;
  r.path = path;
  r.nx = GDALGetRasterXSize(ds.get());
  r.ny = GDALGetRasterYSize(ds.get());
  if (GDALGetRasterCount(ds.get()) < 1) throw Error(ExitCode::data, path + ": has no band");
  r.has_transform = GDALGetGeoTransform(ds.get(), r.transform) == CE_None;
  if (const char* wkt = GDALGetProjectionRef(ds.get())) r.crs_wkt = wkt;
  GDALRasterBandH band = GDALGetRasterBand(ds.get(), 1);
  r.values.resize(static_cast<std::size_t>(r.nx) * static_cast<std::size_t>(r.ny));
  CPLPushErrorHandler(CPLQuietErrorHandler);
  const CPLErr err =
      GDALRasterIO(band, GF_Read, 0, 0, r.nx, r.ny, r.values.data(), r.nx, r.ny, GDT_Float64, 0, 0);
  const std::string read_msg = CPLGetLastErrorMsg();
  CPLPopErrorHandler();
  if (err != CE_None)
    throw Error(ExitCode::io, fmt::format("{}: reading failed: {}", path, read_msg));
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  const double scale = GDALGetRasterScale(band, nullptr);
  const double offset = GDALGetRasterOffset(band, nullptr);
  for (auto& v : r.values) {
    if ((has_nodata && (v == nodata || (std::isnan(nodata) && std::isnan(v)))) || !std::isfinite(v))
      v = std::nan("");
    else
      v = v * scale + offset;
  }
  return r;
}

/// Field `field` of a result file at snapshot `index`, as a Raster.
Raster read_snapshot(const io::ResultReader& r, const std::string& field, std::size_t index) {
  Raster out;
  out.path = fmt::format("{} ({} at t = {:g} s)", r.path(), field, r.times()[index]);
  const Grid& g = r.grid();
  out.nx = g.nx;
  out.ny = g.ny;
  out.has_transform = g.georef.has_transform;
  std::copy(g.georef.transform.begin(), g.georef.transform.end(), out.transform);
  out.crs_wkt = g.georef.crs_wkt;
  const auto v = r.read_index(field, index);
  out.values.assign(v.begin(), v.end());
  for (auto& x : out.values)
    if (!std::isfinite(x)) x = std::nan("");
  return out;
}

/// Whether two CRS are the same; true when either is unknown (nothing to compare).
bool same_crs(const std::string& a, const std::string& b) {
  if (a == b || a.empty() || b.empty()) return true;
  OGRSpatialReferenceH sa = OSRNewSpatialReference(a.c_str());
  OGRSpatialReferenceH sb = OSRNewSpatialReference(b.c_str());
  const bool same = sa && sb && OSRIsSame(sa, sb);
  if (sa) OSRDestroySpatialReference(sa);
  if (sb) OSRDestroySpatialReference(sb);
  return same;
}

/// Both rasters on one grid: size, geotransform (within 1e-6 of a cell) and CRS; else
/// Error(data) naming both files and what differs.
void check_same_grid(const Raster& a, const Raster& b) {
  if (a.nx != b.nx || a.ny != b.ny)
    throw Error(ExitCode::data, fmt::format("grid mismatch: {} is {} x {} cells, {} is {} x {}",
                                            a.path, a.nx, a.ny, b.path, b.nx, b.ny));
  if (a.has_transform != b.has_transform)
    throw Error(ExitCode::data, fmt::format("grid mismatch: {} has {} geotransform, {} has {}",
                                            a.path, a.has_transform ? "a" : "no", b.path,
                                            b.has_transform ? "one" : "none"));
  if (a.has_transform) {
    const double cell = std::max(std::fabs(a.transform[1]), std::fabs(a.transform[5]));
    for (int k = 0; k < 6; ++k)
      if (!(std::fabs(a.transform[k] - b.transform[k]) <= 1e-6 * cell))
        throw Error(ExitCode::data,
                    fmt::format("geotransform mismatch: {} has ({}), {} has ({})", a.path,
                                fmt::join(a.transform, a.transform + 6, ", "), b.path,
                                fmt::join(b.transform, b.transform + 6, ", ")));
  }
  if (!same_crs(a.crs_wkt, b.crs_wkt))
    throw Error(ExitCode::data,
                fmt::format("CRS mismatch: {} and {} are in different CRS{}", a.path, b.path,
                            a.crs_wkt.empty() || b.crs_wkt.empty() ? " (one has none)" : ""));
}

/// One field compared at one time.
struct Difference {
  std::size_t cells = 0;           ///< cells valid in both
  std::size_t valid_mismatch = 0;  ///< cells valid (not NaN) in one and nodata in the other
  double rel_l2 = 0.0;             ///< ||a - b|| / ||b||; 0 when both are 0, inf when only b is
  double max_abs = 0.0;
  int max_col = -1, max_row = -1;  ///< -1: no difference
};

Difference difference(const Raster& a, const Raster& b) {
  Difference r;
  double diff2 = 0.0, ref2 = 0.0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const double va = a.values[i], vb = b.values[i];
    const bool na = std::isnan(va), nb = std::isnan(vb);
    if (na || nb) {
      if (na != nb) ++r.valid_mismatch;
      continue;
    }
    ++r.cells;
    const double d = va - vb;
    diff2 += d * d;
    ref2 += vb * vb;
    if (std::fabs(d) > r.max_abs) {
      r.max_abs = std::fabs(d);
      r.max_col = static_cast<int>(i % static_cast<std::size_t>(a.nx));
      r.max_row = static_cast<int>(i / static_cast<std::size_t>(a.nx));
    }
  }
  r.rel_l2 = ref2 > 0     ? std::sqrt(diff2 / ref2)
             : diff2 == 0 ? 0.0
                          : std::numeric_limits<double>::infinity();
  return r;
}

/// One field over all matching times: the worst relative L2 and the largest difference.
struct FieldResult {
  std::string field;
  std::size_t times = 0;           ///< snapshot times compared
  std::size_t cells = 0;           ///< cells valid in both (at the last time)
  std::size_t valid_mismatch = 0;  ///< the most at any time
  double rel_l2 = 0.0;             ///< the largest at any time
  double rel_l2_time = std::nan("");
  double max_abs = 0.0;  ///< the largest at any time
  double max_abs_time = std::nan("");
  int max_col = -1, max_row = -1;
  bool ok = true;
};

/// A snapshot of each side to compare; index -1 is a GeoTIFF's one state.
struct TimePair {
  double time = std::nan("");  ///< s; NaN when neither side is a result file
  long ia = -1, ib = -1;
};

/// Result file against result file: every snapshot time both hold (to 1e-9 relative);
/// none -> Error(data). A result file against GeoTIFFs: its last snapshot.
std::vector<TimePair> matching_times(const Output& a, const Output& b) {
  if (a.h5 && b.h5) {
    const auto &ta = a.h5->times(), &tb = b.h5->times();
    std::vector<TimePair> out;
    for (std::size_t i = 0; i < ta.size(); ++i)
      for (std::size_t j = 0; j < tb.size(); ++j)
        if (std::fabs(ta[i] - tb[j]) <= 1e-9 * std::max(1.0, std::fabs(ta[i]))) {
          out.push_back({ta[i], static_cast<long>(i), static_cast<long>(j)});
          break;
        }
    if (out.empty())
      throw Error(ExitCode::data,
                  fmt::format("no snapshot time in common: {} has t = {} s, {} has t = {} s",
                              a.path, fmt::join(ta, ", "), b.path, fmt::join(tb, ", ")));
    return out;
  }
  TimePair p;
  if (a.h5 && !a.h5->times().empty()) {
    p.ia = static_cast<long>(a.h5->times().size()) - 1;
    p.time = a.h5->times().back();
  }
  if (b.h5 && !b.h5->times().empty()) {
    p.ib = static_cast<long>(b.h5->times().size()) - 1;
    p.time = b.h5->times().back();
  }
  if ((a.h5 && p.ia < 0) || (b.h5 && p.ib < 0))
    throw Error(ExitCode::data, (a.h5 && p.ia < 0 ? a.path : b.path) + ": holds no snapshot");
  return {p};
}

Raster load(const Output& o, const std::string& field, long index) {
  if (o.h5) return read_snapshot(*o.h5, field, static_cast<std::size_t>(index));
  return read_raster(o.files.count(field) ? o.files.at(field) : o.files.begin()->second);
}

std::string json_time(double t) {
  return json_number(t);
}

int compare(const CompareOptions& o) {
  if (!(o.tol >= 0)) throw Error(ExitCode::usage, "--tol: expected a number >= 0");
  const auto wanted = split_list(o.fields);
  for (const auto& f : wanted) {
    try {
      field_info(f);
    } catch (const Error& e) {  // names the accepted fields
      throw Error(ExitCode::usage, std::string("--fields: ") + e.what());
    }
  }
  const Output a = resolve(o.a), b = resolve(o.b);
  // The fields to compare, each named as A and B hold it ("" for an unnamed GeoTIFF).
  struct Pair {
    std::string label, in_a, in_b;
  };
  std::vector<Pair> pairs;
  if (a.single && b.single) {
    const std::string name = !wanted.empty()                   ? wanted.front()
                             : !a.files.begin()->first.empty() ? a.files.begin()->first
                             : !b.files.begin()->first.empty() ? b.files.begin()->first
                                                               : "band 1";
    pairs.push_back({name, a.files.begin()->first, b.files.begin()->first});
  } else if (a.single || b.single) {
    const Output& one = a.single ? a : b;
    const Output& other = a.single ? b : a;
    const std::string name = !wanted.empty() ? wanted.front() : one.files.begin()->first;
    if (name.empty())
      throw Error(
          ExitCode::usage,
          fmt::format("{}: cannot tell which field it holds; name it with --fields", one.path));
    if (!other.has(name)) throw Error(ExitCode::no_input, other.missing(name));
    pairs.push_back(
        {name, a.single ? a.files.begin()->first : name, b.single ? b.files.begin()->first : name});
  } else {
    std::vector<std::string> names = wanted;
    if (names.empty()) {
      const auto fa = a.fields(), fb = b.fields();
      names = fa;
      for (const auto& f : fb)
        if (std::find(names.begin(), names.end(), f) == names.end()) names.push_back(f);
    }
    for (const auto& name : names) {
      for (const Output* side : {&a, &b})
        if (!side->has(name))
          throw Error(ExitCode::no_input,
                      side->missing(name) +
                          (wanted.empty() ? " (choose the fields to compare with --fields)" : ""));
      pairs.push_back({name, name, name});
    }
  }
  const auto times = matching_times(a, b);
  if (a.h5 && b.h5 &&
      (times.size() != a.h5->times().size() || times.size() != b.h5->times().size()))
    std::fprintf(stderr,
                 "erodem: note: compared the %zu snapshot times both hold (A has %zu, B %zu)\n",
                 times.size(), a.h5->times().size(), b.h5->times().size());

  std::vector<FieldResult> results;
  int nx = 0, ny = 0;
  for (const auto& pair : pairs) {
    FieldResult r;
    r.field = pair.label;
    for (const auto& t : times) {
      const Raster ra = load(a, pair.in_a, t.ia), rb = load(b, pair.in_b, t.ib);
      check_same_grid(ra, rb);
      nx = ra.nx;
      ny = ra.ny;
      const Difference d = difference(ra, rb);
      ++r.times;
      r.cells = d.cells;
      r.valid_mismatch = std::max(r.valid_mismatch, d.valid_mismatch);
      if (d.rel_l2 > r.rel_l2 || r.times == 1) {
        r.rel_l2 = d.rel_l2;
        r.rel_l2_time = t.time;
      }
      if (d.max_abs > r.max_abs) {
        r.max_abs = d.max_abs;
        r.max_abs_time = t.time;
        r.max_col = d.max_col;
        r.max_row = d.max_row;
      }
    }
    r.ok = r.rel_l2 <= o.tol && r.valid_mismatch == 0;
    results.push_back(r);
  }
  const auto failed = static_cast<std::size_t>(
      std::count_if(results.begin(), results.end(), [](const FieldResult& r) { return !r.ok; }));
  std::vector<double> time_list;
  for (const auto& t : times)
    if (!std::isnan(t.time)) time_list.push_back(t.time);

  if (o.json) {
    std::string tl;
    for (double t : time_list) tl += (tl.empty() ? "" : ", ") + json_time(t);
    std::printf(
        "{\"a\": %s, \"b\": %s, \"tol\": %s, \"grid\": [%d, %d], \"times\": [%s], "
        "\"fields\": [",
        json_string(o.a).c_str(), json_string(o.b).c_str(), json_number(o.tol).c_str(), nx, ny,
        tl.c_str());
    for (std::size_t k = 0; k < results.size(); ++k) {
      const auto& r = results[k];
      std::printf(
          "%s\n  {\"field\": %s, \"times\": %zu, \"cells\": %zu, \"valid_mismatch\": %zu, "
          "\"rel_l2\": %s, \"rel_l2_time\": %s, \"max_abs\": %s, \"max_abs_at\": %s, "
          "\"max_abs_time\": %s, \"ok\": %s}",
          k == 0 ? "" : ",", json_string(r.field).c_str(), r.times, r.cells, r.valid_mismatch,
          json_number(r.rel_l2).c_str(), json_time(r.rel_l2_time).c_str(),
          json_number(r.max_abs).c_str(),
          r.max_col < 0 ? "null" : fmt::format("[{}, {}]", r.max_col, r.max_row).c_str(),
          json_time(r.max_abs_time).c_str(), r.ok ? "true" : "false");
    }
    std::printf("\n ], \"failed\": %zu, \"ok\": %s}\n", failed, failed == 0 ? "true" : "false");
  } else {
    std::printf("A: %s\nB: %s\ngrid %d x %d, tolerance %g on ||A - B|| / ||B||, ", o.a.c_str(),
                o.b.c_str(), nx, ny, o.tol);
    if (time_list.empty())
      std::printf("one state (GeoTIFF)\n");
    else if (time_list.size() == 1)
      std::printf("at t = %g s\n", time_list.front());
    else
      std::printf("at %zu times, t = %g .. %g s (worst time shown)\n", time_list.size(),
                  time_list.front(), time_list.back());
    std::printf("%-14s %10s %12s %12s %14s %10s %8s  %s\n", "field", "cells", "rel_L2", "max_abs",
                "at (col,row)", "at t (s)", "nodata", "result");
    for (const auto& r : results) {
      const std::string at = r.max_col < 0 ? "-" : fmt::format("({},{})", r.max_col, r.max_row);
      const std::string when =
          r.max_col < 0 || std::isnan(r.max_abs_time) ? "-" : fmt::format("{:g}", r.max_abs_time);
      std::printf("%-14s %10zu %12.4e %12.4e %14s %10s %8zu  %s\n", r.field.c_str(), r.cells,
                  r.rel_l2, r.max_abs, at.c_str(), when.c_str(), r.valid_mismatch,
                  r.ok                    ? "ok"
                  : r.valid_mismatch != 0 ? "FAIL (nodata differs)"
                                          : "FAIL");
    }
    if (failed == 0)
      std::printf(results.size() == 1 ? "the field is within tolerance\n"
                                      : "all %zu fields within tolerance\n",
                  results.size());
    else
      std::printf("%zu of %zu field%s %s the tolerance\n", failed, results.size(),
                  results.size() == 1 ? "" : "s", failed == 1 ? "fails" : "fail");
  }
  return failed == 0 ? 0 : static_cast<int>(ExitCode::check_failed);
}

}  // namespace

Action add_compare(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* sub = app.add_subcommand(
      "compare", "Relative L2 and max abs difference per field between two run outputs");
  sub->add_option("A", o->a, "Result file (.h5), GeoTIFF fields of a run, or a GeoTIFF")
      ->required();
  sub->add_option("B", o->b, "The reference, in the same forms")->required();
  sub->add_option("--tol", o->tol, "Largest relative L2 difference that passes");
  sub->add_option("--fields", o->fields, "Comma-separated fields to compare (default: all)");
  sub->add_flag("--json", o->json, "Machine-readable output");
  return [o] { return compare(*o); };
}

}  // namespace erodem::cli
