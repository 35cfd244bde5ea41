// erodem — raster input and output through GDAL. See raster.hpp.
#include "erodem/io/raster.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <sstream>
#include <system_error>

#include "erodem/error.hpp"
#include "erodem/io/geodesy.hpp"

namespace erodem::io {
namespace {

namespace fs = std::filesystem;

// ---- GDAL set-up, handles and errors -------------------------------------------------

void ensure_gdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

/// Silences GDAL's messages on this thread for its lifetime and resets the last error, so
/// that the last CPL error can become the erodem::Error message.
class QuietGdal {
 public:
  QuietGdal() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

/// ": <last GDAL message>" or "" when there is none.
std::string gdal_reason() {
  const char* msg = CPLGetLastErrorMsg();
  if (msg == nullptr || *msg == '\0') return "";
  return std::string(": ") + msg;
}

struct DatasetCloser {
  void operator()(void* ds) const {
    if (ds != nullptr) GDALClose(static_cast<GDALDatasetH>(ds));
  }
};
using Dataset = std::unique_ptr<void, DatasetCloser>;

struct SrsDestroyer {
  void operator()(void* srs) const {
    if (srs != nullptr) OSRDestroySpatialReference(static_cast<OGRSpatialReferenceH>(srs));
  }
};
using Srs = std::unique_ptr<void, SrsDestroyer>;

struct CplFree {
  void operator()(char* p) const { CPLFree(p); }
};

std::string window_text(const std::array<int, 4>& w) {
  return "[" + std::to_string(w[0]) + ", " + std::to_string(w[1]) + ", " + std::to_string(w[2]) +
         ", " + std::to_string(w[3]) + "]";
}

std::string size_text(int nx, int ny) {
  return std::to_string(nx) + " x " + std::to_string(ny);
}

bool is_vsi(const std::string& path) {
  return path.rfind("/vsi", 0) == 0;
}

/// Opens a raster read-only; `prefix` starts every error message.
Dataset open_raster(const std::string& path, const std::string& prefix) {
  if (path.empty()) throw Error(ExitCode::config, prefix + "no file given");
  if (!is_vsi(path)) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(ExitCode::no_input, prefix + path + ": no such file");
  }
  CPLErrorReset();
  Dataset ds(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                        nullptr, nullptr, nullptr));
  if (!ds)
    throw Error(ExitCode::data, prefix + path + ": not a raster GDAL can read" + gdal_reason());
  if (GDALGetRasterCount(ds.get()) < 1)
    throw Error(ExitCode::data, prefix + path + ": has no raster band");
  return ds;
}

/// The pixel window to read: the whole raster, or `window` checked against it.
std::array<int, 4> checked_window(GDALDatasetH ds, const std::optional<std::array<int, 4>>& window,
                                  const std::string& prefix, const std::string& path) {
  const int xs = GDALGetRasterXSize(ds), ys = GDALGetRasterYSize(ds);
  if (!window) return {0, 0, xs, ys};
  const auto& w = *window;
  const bool inside = w[0] >= 0 && w[1] >= 0 && w[2] >= 1 && w[3] >= 1 &&
                      static_cast<long long>(w[0]) + w[2] <= xs &&
                      static_cast<long long>(w[1]) + w[3] <= ys;
  if (!inside)
    throw Error(ExitCode::data, prefix + path + ": window " + window_text(w) +
                                    " (col, row, width, height) is not inside the raster (" +
                                    size_text(xs, ys) + ")");
  return w;
}

/// Band 1 of the window as double, with the band's scale and offset applied; `valid`
/// receives 1 for valid cells and 0 for nodata / masked / non-finite ones.
std::vector<double> read_band(GDALDatasetH ds, const std::array<int, 4>& w,
                              std::vector<std::uint8_t>& valid, const std::string& prefix,
                              const std::string& path) {
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  const std::size_t n = static_cast<std::size_t>(w[2]) * static_cast<std::size_t>(w[3]);
  std::vector<double> v(n);
  CPLErrorReset();
  if (GDALRasterIO(band, GF_Read, w[0], w[1], w[2], w[3], v.data(), w[2], w[3], GDT_Float64, 0,
                   0) != CE_None)
    throw Error(ExitCode::data, prefix + path + ": cannot read band 1" + gdal_reason());

  valid.assign(n, 1);
  const int flags = GDALGetMaskFlags(band);
  if ((flags & GMF_ALL_VALID) == 0) {
    // The mask band covers nodata values, per-dataset masks and alpha bands.
    GDALRasterBandH mask = GDALGetMaskBand(band);
    if (mask == nullptr || GDALRasterIO(mask, GF_Read, w[0], w[1], w[2], w[3], valid.data(), w[2],
                                        w[3], GDT_Byte, 0, 0) != CE_None)
      throw Error(ExitCode::data, prefix + path + ": cannot read the nodata mask" + gdal_reason());
  }
  int has_scale = 0, has_offset = 0;
  const double scale = GDALGetRasterScale(band, &has_scale);
  const double offset = GDALGetRasterOffset(band, &has_offset);
  const bool transform = (has_scale && scale != 1.0) || (has_offset && offset != 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (valid[i] != 0 && std::isfinite(v[i])) {
      valid[i] = 1;
      if (transform) v[i] = v[i] * (has_scale ? scale : 1.0) + (has_offset ? offset : 0.0);
    } else {
      valid[i] = 0;
      v[i] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  return v;
}

/// WKT (WKT1, as GDAL writes into GeoTIFFs) of a spatial reference; `what` names it in
/// errors.
std::string wkt_of(OGRSpatialReferenceH h, const std::string& what) {
  char* wkt = nullptr;
  if (OSRExportToWkt(h, &wkt) != OGRERR_NONE || wkt == nullptr) {
    CPLFree(wkt);
    throw config_error("dem.crs", "'" + what + "' cannot be written as WKT");
  }
  std::unique_ptr<char, CplFree> owned(wkt);
  return std::string(wkt);
}

/// Parses a user CRS ("EPSG:32610", "EPSG:4326", WKT, PROJ string). Returns the WKT;
/// sets `geographic` and, for a projected (or local) CRS, `metres_per_unit`.
std::string user_crs_wkt(const std::string& crs, double& metres_per_unit, bool& geographic) {
  Srs srs(OSRNewSpatialReference(nullptr));
  CPLErrorReset();
  auto h = static_cast<OGRSpatialReferenceH>(srs.get());
  if (OSRSetFromUserInput(h, crs.c_str()) != OGRERR_NONE)
    throw config_error("dem.crs", "'" + crs + "' is not a CRS GDAL recognises" + gdal_reason());
  geographic = OSRIsGeographic(h) != 0;
  if (!geographic && OSRIsProjected(h) == 0 && OSRIsLocal(h) == 0)
    throw config_error("dem.crs", "'" + crs +
                                      "' is neither a projected nor a geographic (lat/lon) CRS "
                                      "(a geocentric or vertical CRS cannot place a raster)");
  metres_per_unit = geographic ? 1.0 : OSRGetLinearUnits(h, nullptr);
  return wkt_of(h, crs);
}

/// Degrees per angular unit of a geographic CRS (1 for degrees, snapped so that the WKT's
/// rounded radian value of a degree does not scale every coordinate by 1 + 3e-16).
double degrees_per_unit(OGRSpatialReferenceH h) {
  const double radians = OSRGetAngularUnits(h, nullptr);
  const double degrees = radians * 180.0 / 3.14159265358979323846;
  return std::fabs(degrees - 1.0) < 1e-12 ? 1.0 : degrees;
}

/// The ellipsoid of a geographic (or projected) CRS; `what` names the source in errors.
Ellipsoid ellipsoid_of(OGRSpatialReferenceH h, const std::string& what) {
  OGRErr err_a = OGRERR_NONE, err_f = OGRERR_NONE;
  Ellipsoid e;
  e.semi_major = OSRGetSemiMajor(h, &err_a);
  e.inverse_flattening = OSRGetInvFlattening(h, &err_f);
  const char* name = OSRGetAttrValue(h, "SPHEROID", 0);
  e.name = name != nullptr ? name : "";
  if (err_a != OGRERR_NONE || err_f != OGRERR_NONE)
    throw Error(ExitCode::data, what + ": its CRS names no ellipsoid");
  e.validate(what);
  return e;
}

/// Cell sizes and areas of a lat/lon grid (g.nx, g.ny set) whose geotransform `gt` (already
/// shifted to the window) is in the angular unit of geographic CRS `h`.
void set_geographic_grid(Grid& g, OGRSpatialReferenceH h, const std::array<double, 6>& gt,
                         const std::string& what) {
  if (gt[2] != 0.0 || gt[4] != 0.0)
    throw Error(ExitCode::data, what + ": rotated geotransforms are not supported");
  const double deg = degrees_per_unit(h);
  set_geographic_rows(g, ellipsoid_of(h, what), gt[3] * deg, gt[5] * deg, gt[1] * deg, what);
}

/// A spatial reference parsed from WKT (or any user input GDAL takes); null when it fails.
Srs parse_srs(const std::string& text) {
  Srs srs(OSRNewSpatialReference(nullptr));
  if (OSRSetFromUserInput(static_cast<OGRSpatialReferenceH>(srs.get()), text.c_str()) !=
      OGRERR_NONE)
    return Srs();
  return srs;
}

/// Sets constant per-row cell sizes dx, dy (m) and areas for all g.ny rows.
void set_uniform_rows(Grid& g, double dx, double dy) {
  g.dx.assign(static_cast<std::size_t>(g.ny), dx);
  g.dy.assign(static_cast<std::size_t>(g.ny), dy);
  g.area.assign(static_cast<std::size_t>(g.ny), dx * dy);
}

/// The geotransform shifted to the top-left corner of pixel (col, row).
std::array<double, 6> shifted(const std::array<double, 6>& t, int col, int row) {
  return {t[0] + col * t[1] + row * t[2], t[1], t[2], t[3] + col * t[4] + row * t[5], t[4], t[5]};
}

constexpr const char* kUnitsKey = "ERODEM_CRS_UNITS";

// ---- SHA-256 (FIPS 180-4) ---------------------------------------------------------------

class Sha256 {
 public:
  void update(const unsigned char* p, std::size_t n) {
    total_ += n;
    while (n > 0) {
      const std::size_t take = std::min(n, static_cast<std::size_t>(64) - used_);
      std::copy(p, p + take, block_ + used_);
      used_ += take;
      p += take;
      n -= take;
      if (used_ == 64) {
        compress(block_);
        used_ = 0;
      }
    }
  }
  std::string hex() {
    const std::uint64_t bits = total_ * 8;
    const unsigned char pad = 0x80;
    update(&pad, 1);
    const unsigned char zero = 0;
    while (used_ != 56) update(&zero, 1);
    unsigned char len[8];
    for (int i = 0; i < 8; ++i) len[i] = static_cast<unsigned char>(bits >> (56 - 8 * i));
    update(len, 8);
    static const char* digits = "0123456789abcdef";
    std::string out;
    for (std::uint32_t word : h_)
      for (int s = 28; s >= 0; s -= 4) out += digits[(word >> s) & 0xF];
    return out;
  }

 private:
  static std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }
  void compress(const unsigned char* b) {
    static const std::uint32_t k[64] = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
        0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
        0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
        0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
        0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
        0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
        0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
        0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2};
    std::uint32_t w[64];
    for (int i = 0; i < 16; ++i)
      w[i] = (std::uint32_t(b[4 * i]) << 24) | (std::uint32_t(b[4 * i + 1]) << 16) |
             (std::uint32_t(b[4 * i + 2]) << 8) | std::uint32_t(b[4 * i + 3]);
    for (int i = 16; i < 64; ++i) {
      const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::uint32_t a = h_[0], bb = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6],
                  h = h_[7];
    for (int i = 0; i < 64; ++i) {
      const std::uint32_t t1 =
          h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + k[i] + w[i];
      const std::uint32_t t2 =
          (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & bb) ^ (a & c) ^ (bb & c));
      h = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = bb;
      bb = a;
      a = t1 + t2;
    }
    h_[0] += a;
    h_[1] += bb;
    h_[2] += c;
    h_[3] += d;
    h_[4] += e;
    h_[5] += f;
    h_[6] += g;
    h_[7] += h;
  }

  std::uint32_t h_[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                         0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  unsigned char block_[64] = {};
  std::size_t used_ = 0;
  std::uint64_t total_ = 0;
};

struct VsiCloser {
  void operator()(VSILFILE* f) const {
    if (f != nullptr) VSIFCloseL(f);
  }
};

}  // namespace

std::string sha256_hex(const void* data, std::size_t size) {
  Sha256 s;
  s.update(static_cast<const unsigned char*>(data), size);
  return s.hex();
}

std::string file_sha256(const std::string& path) {
  ensure_gdal();
  QuietGdal quiet;
  std::unique_ptr<VSILFILE, VsiCloser> f(VSIFOpenL(path.c_str(), "rb"));
  if (!f) throw Error(ExitCode::no_input, path + ": cannot open to compute its checksum");
  Sha256 s;
  std::vector<unsigned char> buf(1 << 20);
  for (;;) {
    const std::size_t got = VSIFReadL(buf.data(), 1, buf.size(), f.get());
    s.update(buf.data(), got);
    if (got < buf.size()) {
      if (VSIFEofL(f.get()) == 0)
        throw Error(ExitCode::io, path + ": read error while computing its checksum");
      break;
    }
  }
  return s.hex();
}

Terrain read_dem(const Params::Dem& dem) {
  ensure_gdal();
  QuietGdal quiet;
  const std::string& path = dem.path;
  if (path.empty()) throw config_error("dem.path", "no DEM file given");
  if (!(std::isfinite(dem.z_scale) && dem.z_scale != 0.0))
    throw config_error("dem.z_scale", "must be a finite non-zero number");
  if (!(std::isfinite(dem.cell_size) && dem.cell_size >= 0.0))
    throw config_error("dem.cell_size", "must be a positive length (m)");

  Dataset ds = open_raster(path, "");
  GDALDatasetH h = ds.get();
  const std::array<int, 4> w = checked_window(h, dem.window, "", path);

  Terrain t;
  Grid& g = t.grid;

  // Georeferencing.
  std::array<double, 6> gt{};
  const bool has_gt = GDALGetGeoTransform(h, gt.data()) == CE_None;
  OGRSpatialReferenceH file_srs = GDALGetSpatialRef(h);  // owned by the dataset
  const char* units_tag = GDALGetMetadataItem(h, kUnitsKey, nullptr);
  const bool erodem_metres =
      has_gt && file_srs == nullptr && units_tag != nullptr && std::string(units_tag) == "metre";
  const bool georeferenced = has_gt && (file_srs != nullptr || erodem_metres);

  if (georeferenced) {
    if (dem.cell_size > 0.0)
      throw config_error("dem.cell_size", path +
                                              " has its own georeferencing; dem.cell_size is only "
                                              "for files without it");
    if (!dem.crs.empty())
      throw config_error("dem.crs", path +
                                        " has its own georeferencing; dem.crs is only for files "
                                        "without it");
    g.nx = w[2];
    g.ny = w[3];
    g.georef.transform = shifted(gt, w[0], w[1]);
    g.georef.has_transform = true;
    if (file_srs != nullptr) {
      const char* wkt = GDALGetProjectionRef(h);
      g.georef.crs_wkt = wkt != nullptr ? wkt : "";
    }
    if (file_srs != nullptr && OSRIsGeographic(file_srs)) {
      g.georef.is_geographic = true;
      set_geographic_grid(g, file_srs, g.georef.transform, path);
    } else {
      const double metres_per_unit =
          file_srs != nullptr ? OSRGetLinearUnits(file_srs, nullptr) : 1.0;
      if (gt[2] != 0.0 || gt[4] != 0.0)
        throw Error(ExitCode::data, path + ": rotated geotransforms are not supported");
      const double dx = std::fabs(gt[1]) * metres_per_unit;
      const double dy = std::fabs(gt[5]) * metres_per_unit;
      if (!(std::isfinite(dx) && dx > 0.0 && std::isfinite(dy) && dy > 0.0))
        throw Error(ExitCode::data, path + ": invalid pixel size in its geotransform");
      set_uniform_rows(g, dx, dy);
      g.georef.is_geographic = false;
    }
  } else if (dem.cell_size > 0.0) {
    g = Grid::uniform(w[2], w[3], dem.cell_size);
    g.georef.has_transform = false;
    if (!dem.crs.empty()) {
      double metres_per_unit = 1.0;
      bool geographic = false;
      g.georef.crs_wkt = user_crs_wkt(dem.crs, metres_per_unit, geographic);
      if (geographic)
        throw config_error("dem.crs", "'" + dem.crs + "' is geographic (lat/lon) but " + path +
                                          " has no geotransform to place its cells in degrees; "
                                          "dem.cell_size with dem.crs needs a projected CRS");
      // Grid::uniform's transform is in metres; express it in the CRS's unit.
      for (double* v : {&g.georef.transform[0], &g.georef.transform[1], &g.georef.transform[3],
                        &g.georef.transform[5]})
        *v /= metres_per_unit;
    }
  } else if (has_gt && !dem.crs.empty()) {
    double metres_per_unit = 1.0;
    bool geographic = false;
    g.georef.crs_wkt = user_crs_wkt(dem.crs, metres_per_unit, geographic);
    if (gt[2] != 0.0 || gt[4] != 0.0)
      throw Error(ExitCode::data, path + ": rotated geotransforms are not supported");
    g.nx = w[2];
    g.ny = w[3];
    g.georef.transform = shifted(gt, w[0], w[1]);
    g.georef.has_transform = true;
    if (geographic) {
      // The file's transform is taken as degrees (longitude, latitude) on this CRS.
      Srs srs = parse_srs(g.georef.crs_wkt);
      if (!srs) throw config_error("dem.crs", "'" + dem.crs + "' cannot be read back from WKT");
      g.georef.is_geographic = true;
      set_geographic_grid(g, static_cast<OGRSpatialReferenceH>(srs.get()), g.georef.transform,
                          path + " (with dem.crs = '" + dem.crs + "')");
    } else {
      set_uniform_rows(g, std::fabs(gt[1]) * metres_per_unit, std::fabs(gt[5]) * metres_per_unit);
    }
  } else {
    throw Error(ExitCode::config,
                path +
                    ": has no georeferencing; set dem.cell_size (and dem.crs), or dem.crs "
                    "alone when its geotransform is in that CRS's units");
  }
  g.validate();

  // Elevations.
  std::vector<std::uint8_t> valid;
  t.bed = read_band(h, w, valid, "", path);
  std::size_t n_valid = 0;
  for (std::size_t i = 0; i < t.bed.size(); ++i) {
    // dem.nodata_value marks cells of a file that declares no nodata (e.g. sea at 0).
    if (dem.nodata_value && t.bed[i] == *dem.nodata_value) valid[i] = 0;
    if (valid[i] != 0) {
      t.bed[i] *= dem.z_scale;
      ++n_valid;
    } else {
      t.bed[i] = std::nan("");
    }
  }
  if (n_valid == 0)
    throw Error(ExitCode::data, path + ": no valid (non-nodata) cells" +
                                    (dem.window ? " in window " + window_text(*dem.window) : ""));
  if (n_valid < t.bed.size()) t.mask = std::move(valid);
  ds.reset();

  t.source = path;
  t.source_sha256 = file_sha256(path);
  const int factor = resample_factor(dem, g);
  return factor > 1 ? coarsen(t, factor) : t;
}

int resample_factor(const Params::Dem& dem, const Grid& grid) {
  if (dem.resample_factor > 0) return dem.resample_factor;
  if (!(dem.resample > 0.0)) return 1;
  if (grid.georef.is_geographic)
    throw config_error("dem.resample",
                       "a cell size in metres cannot coarsen the geographic (lat/lon) grid of " +
                           dem.path +
                           ", whose east-west cell size varies by row; give an "
                           "integer factor (dem.resample = 4)");
  const double cell = grid.dx.empty() ? 0.0 : grid.dx[0];
  const double f = dem.resample / cell;
  const long n = std::lround(f);
  if (n < 1 || std::fabs(f - static_cast<double>(n)) > 1e-6 * f)
    throw config_error("dem.resample",
                       std::to_string(dem.resample) + " m is not a whole multiple of the " +
                           std::to_string(cell) + " m cell of " + dem.path + "; the nearest is " +
                           std::to_string(std::max(1L, n) * cell) +
                           " m (or give an integer factor)");
  return static_cast<int>(n);
}

Terrain coarsen(const Terrain& fine, int factor) {
  const Grid& g = fine.grid;
  if (factor < 1) throw config_error("dem.resample", "the factor must be at least 1");
  const int nx = g.nx / factor, ny = g.ny / factor;
  if (nx < 1 || ny < 1)
    throw config_error("dem.resample", "a factor of " + std::to_string(factor) +
                                           " leaves no cell of the " + std::to_string(g.nx) +
                                           " x " + std::to_string(g.ny) + " grid");
  Terrain t;
  t.source =
      fine.source + " (averaged " + std::to_string(factor) + "x" + std::to_string(factor) + ")";
  t.source_sha256 = fine.source_sha256;
  Grid& c = t.grid;
  c.nx = nx;
  c.ny = ny;
  c.georef = g.georef;
  for (int k : {1, 2, 4, 5}) c.georef.transform[k] *= factor;
  for (int r = 0; r < ny; ++r) {
    double dx = 0, dy = 0, area = 0;
    for (int k = 0; k < factor; ++k) {
      dx += g.dx[r * factor + k] / factor;
      dy += g.dy[r * factor + k];
      area += g.area[r * factor + k] * factor;
    }
    c.dx.push_back(dx * factor);
    c.dy.push_back(dy);
    c.area.push_back(area);
  }
  if (c.georef.is_geographic) {
    // Exact sizes of the coarse cells, from the ellipsoid of the grid's CRS.
    Srs srs = parse_srs(c.georef.crs_wkt);
    if (!srs) throw Error(ExitCode::internal, t.source + ": geographic grid without a usable CRS");
    set_geographic_grid(c, static_cast<OGRSpatialReferenceH>(srs.get()), c.georef.transform,
                        t.source);
  }
  // Block averages over the valid cells; a block with none stays nodata. One helper serves
  // the bed and every parameter raster, so they average over the same cells.
  auto block_mean = [&](const std::vector<double>& v, int r, int col, double& mean) {
    double sum = 0;
    int n = 0;
    for (int i = 0; i < factor; ++i)
      for (int j = 0; j < factor; ++j) {
        const auto k = static_cast<std::size_t>(r * factor + i) * g.nx + (col * factor + j);
        if (!fine.active(k)) continue;
        sum += v[k];
        ++n;
      }
    mean = n > 0 ? sum / n : 0.0;
    return n > 0;
  };
  t.bed.assign(c.cells(), std::nan(""));
  std::vector<std::uint8_t> mask(c.cells(), 0);
  bool any_masked = false;
  for (int r = 0; r < ny; ++r)
    for (int col = 0; col < nx; ++col) {
      const auto o = static_cast<std::size_t>(r) * nx + col;
      double mean = 0;
      if (block_mean(fine.bed, r, col, mean)) {
        t.bed[o] = mean;
        mask[o] = 1;
      } else {
        any_masked = true;
      }
    }
  if (any_masked) t.mask = std::move(mask);
  // Parameter rasters on the fine grid (0 where a block has no valid cell).
  auto average = [&](const std::vector<double>& v) {
    std::vector<double> out;
    if (v.empty()) return out;
    out.assign(c.cells(), 0.0);
    for (int r = 0; r < ny; ++r)
      for (int col = 0; col < nx; ++col)
        block_mean(v, r, col, out[static_cast<std::size_t>(r) * nx + col]);
    return out;
  };
  t.water_depth = average(fine.water_depth);
  t.manning_n = average(fine.manning_n);
  t.hardness = average(fine.hardness);
  t.rain_factor = average(fine.rain_factor);
  return t;
}

RasterHeader read_raster_header(const std::string& path) {
  ensure_gdal();
  QuietGdal quiet;
  Dataset ds = open_raster(path, "");
  GDALDatasetH h = ds.get();
  RasterHeader r;
  GDALDriverH drv = GDALGetDatasetDriver(h);
  if (drv != nullptr) {
    r.driver = GDALGetDriverShortName(drv);
    r.driver_long = GDALGetDriverLongName(drv);
  }
  r.nx = GDALGetRasterXSize(h);
  r.ny = GDALGetRasterYSize(h);
  r.bands = GDALGetRasterCount(h);
  GDALRasterBandH band = GDALGetRasterBand(h, 1);
  r.data_type = GDALGetDataTypeName(GDALGetRasterDataType(band));
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) r.nodata = nodata;
  r.has_transform = GDALGetGeoTransform(h, r.transform.data()) == CE_None;
  if (GDALGetSpatialRef(h) != nullptr) {
    const char* wkt = GDALGetProjectionRef(h);
    r.crs_wkt = wkt != nullptr ? wkt : "";
  }
  const char* units_tag = GDALGetMetadataItem(h, kUnitsKey, nullptr);
  r.erodem_metres = r.has_transform && r.crs_wkt.empty() && units_tag != nullptr &&
                    std::string(units_tag) == "metre";
  return r;
}

CrsInfo describe_crs(const std::string& crs) {
  ensure_gdal();
  QuietGdal quiet;
  if (crs.empty()) throw Error(ExitCode::data, "no CRS to describe");
  Srs srs = parse_srs(crs);
  if (!srs) throw Error(ExitCode::data, "not a CRS GDAL recognises" + gdal_reason());
  auto h = static_cast<OGRSpatialReferenceH>(srs.get());
  CrsInfo info;
  const char* name = OSRGetName(h);
  info.name = name != nullptr ? name : "";
  const char* auth = OSRGetAuthorityName(h, nullptr);
  const char* code = OSRGetAuthorityCode(h, nullptr);
  if (auth != nullptr && code != nullptr) {
    info.authority = std::string(auth) + ":" + code;
  } else {
    // A CRS written without its code (e.g. NAD83 in a GeoTIFF's keys): the code of the one
    // CRS of the database that matches it with full confidence, if any.
    int n = 0;
    int* confidence = nullptr;
    OGRSpatialReferenceH* matches = OSRFindMatches(h, nullptr, &n, &confidence);
    if (matches != nullptr && n >= 1 && confidence[0] == 100 && (n == 1 || confidence[1] < 100)) {
      auth = OSRGetAuthorityName(matches[0], nullptr);
      code = OSRGetAuthorityCode(matches[0], nullptr);
      if (auth != nullptr && code != nullptr) info.authority = std::string(auth) + ":" + code;
    }
    OSRFreeSRSArray(matches);
    CPLFree(confidence);
  }
  info.geographic = OSRIsGeographic(h) != 0;
  info.projected = OSRIsProjected(h) != 0;
  char* unit = nullptr;
  if (info.geographic) {
    OSRGetAngularUnits(h, &unit);
    info.unit_factor = degrees_per_unit(h);
  } else {
    info.unit_factor = OSRGetLinearUnits(h, &unit);
  }
  info.unit = unit != nullptr ? unit : "";  // owned by the spatial reference
  OGRErr err_a = OGRERR_NONE, err_f = OGRERR_NONE;
  info.ellipsoid.semi_major = OSRGetSemiMajor(h, &err_a);
  info.ellipsoid.inverse_flattening = OSRGetInvFlattening(h, &err_f);
  const char* ell = OSRGetAttrValue(h, "SPHEROID", 0);
  info.ellipsoid.name = ell != nullptr ? ell : "";
  if (err_a != OGRERR_NONE || err_f != OGRERR_NONE) {
    info.ellipsoid.semi_major = std::nan("");
    info.ellipsoid.inverse_flattening = std::nan("");
  }
  return info;
}

std::vector<double> read_raster_on_grid(const std::string& path, const Grid& grid,
                                        const std::optional<std::array<int, 4>>& window,
                                        const std::string& what) {
  ensure_gdal();
  QuietGdal quiet;
  const std::string prefix = what + ": ";
  Dataset ds = open_raster(path, prefix);
  GDALDatasetH h = ds.get();
  const std::array<int, 4> w = checked_window(h, window, prefix, path);
  if (w[2] != grid.nx || w[3] != grid.ny)
    throw Error(ExitCode::data, prefix + path + " is " + size_text(w[2], w[3]) +
                                    (window ? " (in window " + window_text(*window) + ")" : "") +
                                    " but the DEM grid is " + size_text(grid.nx, grid.ny));
  std::array<double, 6> gt{};
  if (grid.georef.has_transform && GDALGetGeoTransform(h, gt.data()) == CE_None) {
    const auto a = shifted(gt, w[0], w[1]);
    const auto& b = grid.georef.transform;
    const double tol = 1e-6 * std::max(std::fabs(b[1]), std::fabs(b[5]));
    bool same = true;
    for (int k = 0; k < 6; ++k) same = same && std::fabs(a[k] - b[k]) <= tol;
    if (!same) {
      std::ostringstream msg;
      msg.precision(12);
      msg << prefix << path << ": its geotransform (" << a[0] << ", " << a[1] << ", " << a[2]
          << ", " << a[3] << ", " << a[4] << ", " << a[5] << ") does not match the DEM grid's ("
          << b[0] << ", " << b[1] << ", " << b[2] << ", " << b[3] << ", " << b[4] << ", " << b[5]
          << ")";
      throw Error(ExitCode::data, msg.str());
    }
  }
  std::vector<std::uint8_t> valid;
  return read_band(h, w, valid, prefix, path);
}

void write_geotiff(const std::string& path, const Grid& grid, const std::vector<float>& values,
                   const std::string& description, double nodata) {
  ensure_gdal();
  QuietGdal quiet;
  if (grid.nx < 1 || grid.ny < 1 || values.size() != grid.cells())
    throw Error(ExitCode::internal, path + ": " + std::to_string(values.size()) + " values for a " +
                                        size_text(grid.nx, grid.ny) + " grid");
  const fs::path target(path);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(ExitCode::cant_create,
                path + ": cannot create: directory " + dir.string() + " does not exist");

  static std::atomic<unsigned long> counter{0};
  const auto stamp =
      static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp-" + std::to_string(stamp) +
                              "-" + std::to_string(counter++) + ".tif");
  const std::string tmp_s = tmp.string();

  /// Removes the temporary file (and any sidecar GDAL wrote) unless committed. Declared
  /// before the dataset so that the dataset is closed first.
  struct TempGuard {
    std::string file;
    bool committed = false;
    ~TempGuard() {
      if (committed) return;
      std::error_code e;
      fs::remove(file, e);
      fs::remove(file + ".aux.xml", e);
    }
  } guard{tmp_s};

  GDALDriverH drv = GDALGetDriverByName("GTiff");
  if (drv == nullptr) throw Error(ExitCode::internal, "GDAL has no GTiff driver");
  const char* options[] = {"COMPRESS=DEFLATE", "PREDICTOR=3", "TILED=YES", "BIGTIFF=IF_SAFER",
                           nullptr};
  CPLErrorReset();
  Dataset ds(GDALCreate(drv, tmp_s.c_str(), grid.nx, grid.ny, 1, GDT_Float32,
                        const_cast<char**>(options)));
  if (!ds) throw Error(ExitCode::cant_create, path + ": cannot create" + gdal_reason());
  GDALDatasetH h = ds.get();

  std::array<double, 6> gt = grid.georef.transform;
  bool ok = GDALSetGeoTransform(h, gt.data()) == CE_None;
  if (!grid.georef.crs_wkt.empty())
    ok = ok && GDALSetProjection(h, grid.georef.crs_wkt.c_str()) == CE_None;
  else
    ok = ok && GDALSetMetadataItem(h, kUnitsKey, "metre", nullptr) == CE_None;
  if (!description.empty())
    ok = ok && GDALSetMetadataItem(h, "TIFFTAG_IMAGEDESCRIPTION", description.c_str(), nullptr) ==
                   CE_None;
  GDALRasterBandH band = GDALGetRasterBand(h, 1);
  if (!description.empty()) GDALSetDescription(band, description.c_str());
  ok = ok && GDALSetRasterNoDataValue(band, nodata) == CE_None;
  if (!ok) throw Error(ExitCode::io, path + ": cannot write georeferencing" + gdal_reason());

  if (GDALRasterIO(band, GF_Write, 0, 0, grid.nx, grid.ny, const_cast<float*>(values.data()),
                   grid.nx, grid.ny, GDT_Float32, 0, 0) != CE_None)
    throw Error(ExitCode::io, path + ": write failed" + gdal_reason());
  CPLErrorReset();
  GDALFlushCache(h);
  ds.reset();  // GDAL 3.6's GDALClose returns nothing: check the error state instead
  if (CPLGetLastErrorType() == CE_Failure || CPLGetLastErrorType() == CE_Fatal)
    throw Error(ExitCode::io, path + ": write failed" + gdal_reason());

  fs::rename(tmp, target, ec);
  if (ec)
    throw Error(ExitCode::cant_create,
                path + ": cannot move the finished file into place: " + ec.message());
  guard.committed = true;
  std::error_code ignore;
  fs::remove(tmp_s + ".aux.xml", ignore);
}

}  // namespace erodem::io
