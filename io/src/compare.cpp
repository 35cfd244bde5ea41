// erodem — comparing run outputs field by field (compare.hpp): the sides and their fields,
// the GDAL band reads of GeoTIFFs, the grid check, the difference of one field at one time,
// and the snapshot times two outputs share.
#include "erodem/io/compare.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <limits>
#include <system_error>

#include "erodem/error.hpp"
#include "erodem/fields.hpp"

namespace erodem::io {

namespace {

namespace fs = std::filesystem;

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

/// Closes a GDAL dataset on every path.
struct DatasetCloser {
  void operator()(void* ds) const {
    if (ds) GDALClose(ds);
  }
};

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

}  // namespace

bool CompareInput::has(const std::string& field) const {
  if (h5) {
    const auto f = h5->fields();
    return std::find(f.begin(), f.end(), field) != f.end();
  }
  return files.count(field) != 0;
}

std::vector<std::string> CompareInput::fields() const {
  if (h5) return h5->fields();
  std::vector<std::string> out;
  for (const auto& f : field_table())
    if (files.count(f.name)) out.push_back(f.name);
  return out;
}

std::string CompareInput::missing(const std::string& field) const {
  return h5 ? fmt::format("{}: field '{}' missing: the file holds {}", path, field,
                          fmt::join(h5->fields(), ", "))
            : fmt::format("{}: field '{}' missing: no file {}", path, field,
                          field_file(path, field));
}

CompareInput open_compare_input(const std::string& path) {
  CompareInput o;
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
    o.h5 = std::make_shared<ResultReader>(path);  // not a result file -> Error(data)
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

RasterBand read_raster_band(const std::string& path) {
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
  RasterBand r;
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

RasterBand read_snapshot_band(const ResultReader& r, const std::string& field, std::size_t index) {
  RasterBand out;
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

void check_same_grid(const RasterBand& a, const RasterBand& b) {
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

FieldDifference field_difference(const std::vector<double>& a, const std::vector<double>& b,
                                 int nx) {
  FieldDifference r;
  double diff2 = 0.0, ref2 = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double va = a[i], vb = b[i];
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
      r.max_col = static_cast<int>(i % static_cast<std::size_t>(nx));
      r.max_row = static_cast<int>(i / static_cast<std::size_t>(nx));
    }
  }
  r.rel_l2 = ref2 > 0     ? std::sqrt(diff2 / ref2)
             : diff2 == 0 ? 0.0
                          : std::numeric_limits<double>::infinity();
  return r;
}

std::vector<TimePair> matching_times(const CompareInput& a, const CompareInput& b) {
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

RasterBand load_compare_field(const CompareInput& o, const std::string& field, long index) {
  if (o.h5) return read_snapshot_band(*o.h5, field, static_cast<std::size_t>(index));
  return read_raster_band(o.files.count(field) ? o.files.at(field) : o.files.begin()->second);
}

}  // namespace erodem::io
