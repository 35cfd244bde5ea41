// erodem — netCDF variables as rasters in time (raster.hpp): GDAL's NETCDF:"file":var names,
// the variables a file holds, and the band times of a time coordinate (CF units "<unit> since
// <date>").
#include <fmt/format.h>
#include <gdal.h>
#include <gdal_priv.h>

#include <cstdlib>
#include <sstream>

#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {

namespace {

constexpr const char* kNetcdfPrefix = "NETCDF:";

/// The items of a GDAL list "{a,b,c}".
std::vector<std::string> braced_list(const char* text) {
  std::vector<std::string> out;
  if (text == nullptr) return out;
  std::string s(text);
  if (!s.empty() && s.front() == '{') s.erase(0, 1);
  if (!s.empty() && s.back() == '}') s.pop_back();
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// Seconds per unit of a CF time unit ("seconds", "hours", ...); 0 when not one of fixed length.
double seconds_per(const std::string& unit) {
  for (const auto& [names, s] : std::vector<std::pair<std::vector<std::string>, double>>{
           {{"seconds", "second", "secs", "sec", "s"}, 1.0},
           {{"minutes", "minute", "mins", "min"}, 60.0},
           {{"hours", "hour", "hrs", "hr", "h"}, 3600.0},
           {{"days", "day", "d"}, 86400.0}})
    for (const auto& n : names)
      if (unit == n) return s;
  return 0.0;
}

}  // namespace

std::optional<NetcdfName> parse_netcdf_name(const std::string& path) {
  if (path.rfind(kNetcdfPrefix, 0) != 0) return std::nullopt;
  const std::string rest = path.substr(std::string(kNetcdfPrefix).size());
  NetcdfName n;
  if (!rest.empty() && rest.front() == '"') {
    const auto close = rest.find('"', 1);
    if (close == std::string::npos || close + 1 >= rest.size() || rest[close + 1] != ':')
      return std::nullopt;
    n.file = rest.substr(1, close - 1);
    n.variable = rest.substr(close + 2);
  } else {
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos) return std::nullopt;
    n.file = rest.substr(0, colon);
    n.variable = rest.substr(colon + 1);
  }
  if (n.file.empty() || n.variable.empty()) return std::nullopt;
  return n;
}

std::string netcdf_name(const NetcdfName& n) {
  return std::string(kNetcdfPrefix) + "\"" + n.file + "\":" + n.variable;
}

std::vector<std::string> subdataset_variables(GDALDatasetH ds) {
  std::vector<std::string> out;
  char** md = GDALGetMetadata(ds, "SUBDATASETS");
  for (int i = 0; md != nullptr && md[i] != nullptr; ++i) {
    const std::string item(md[i]);
    const auto eq = item.find("_NAME=");
    if (eq == std::string::npos) continue;
    if (const auto n = parse_netcdf_name(item.substr(eq + 6))) out.push_back(n->variable);
  }
  return out;
}

std::vector<std::string> netcdf_variables(const std::string& file) {
  Dataset ds(
      GDALOpenEx(file.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!ds) return {};
  auto vars = subdataset_variables(ds.get());
  // a file of one variable opens as that variable
  if (vars.empty() && GDALGetRasterCount(ds.get()) > 0)
    if (const char* name =
            GDALGetMetadataItem(GDALGetRasterBand(ds.get(), 1), "NETCDF_VARNAME", nullptr))
      vars.emplace_back(name);
  return vars;
}

std::string read_band_units(const std::string& path, const std::string& what) {
  ensure_gdal();
  QuietGdal quiet;
  Dataset ds = open_raster(path, what + ": ");
  const char* units = GDALGetRasterUnitType(GDALGetRasterBand(ds.get(), 1));
  return units != nullptr ? units : "";
}

std::vector<double> read_band_times(const std::string& path, const std::string& what) {
  ensure_gdal();
  QuietGdal quiet;
  const std::string prefix = what + ": ";
  Dataset ds = open_raster(path, prefix);
  GDALDatasetH h = ds.get();
  GDALDriverH drv = GDALGetDatasetDriver(h);
  if (drv == nullptr || std::string(GDALGetDriverShortName(drv)) != "netCDF") return {};
  const auto dims = braced_list(GDALGetMetadataItem(h, "NETCDF_DIM_EXTRA", nullptr));
  if (dims.empty()) return {};
  if (dims.size() > 1)
    throw Error(ExitCode::data,
                fmt::format("{}{}: has the dimensions {{{}}} besides y and x; only one, the time, "
                            "can give the bands",
                            prefix, path, fmt::join(dims, ", ")));
  const std::string dim = dims.front();
  const char* units_text = GDALGetMetadataItem(h, (dim + "#units").c_str(), nullptr);
  const std::string units = units_text != nullptr ? units_text : "";
  const auto since = units.find(" since ");
  const double factor = since == std::string::npos ? 0.0 : seconds_per(units.substr(0, since));
  if (!(factor > 0))
    throw Error(ExitCode::data, fmt::format("{}{}: its time coordinate '{}' has units '{}', not "
                                            "'<seconds|minutes|hours|days> since <date>'",
                                            prefix, path, dim, units));
  const int count = GDALGetRasterCount(h);
  std::vector<double> values;
  for (int b = 1; b <= count; ++b) {
    const char* v =
        GDALGetMetadataItem(GDALGetRasterBand(h, b), ("NETCDF_DIM_" + dim).c_str(), nullptr);
    char* end = nullptr;
    const double x = v != nullptr ? std::strtod(v, &end) : 0.0;
    if (v == nullptr || end == v)
      throw Error(ExitCode::data, fmt::format("{}{}: band {} has no value of its time "
                                              "coordinate '{}'",
                                              prefix, path, b, dim));
    values.push_back(x);
  }
  std::vector<double> times;
  for (int b = 0; b < count; ++b) {
    times.push_back((values[b] - values[0]) * factor);
    if (b > 0 && !(times[b] > times[b - 1]))
      throw Error(
          ExitCode::data,
          fmt::format("{}{}: its time coordinate '{}' does not increase: band {} at {:.10g} "
                      "{} after band {} at {:.10g}",
                      prefix, path, dim, b + 1, values[b], units, b, values[b - 1]));
  }
  return times;
}

void write_netcdf_bands(const std::string& path, const Grid& grid, const std::string& variable,
                        const std::vector<std::vector<float>>& bands, const std::string& time_units,
                        const std::vector<double>& times, const std::string& units) {
  ensure_gdal();
  QuietGdal quiet;
  const auto nx = static_cast<std::size_t>(grid.nx), ny = static_cast<std::size_t>(grid.ny);
  if (times.size() != bands.size())
    throw Error(ExitCode::internal, "write_netcdf_bands: times and bands differ in count");
  GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("netCDF");
  std::unique_ptr<GDALDataset> ds(drv ? drv->CreateMultiDimensional(path.c_str(), nullptr, nullptr)
                                      : nullptr);
  if (!ds) throw Error(ExitCode::cant_create, path + ": cannot create" + gdal_reason());
  auto root = ds->GetRootGroup();
  const auto f64 = GDALExtendedDataType::Create(GDT_Float64);
  const auto f32 = GDALExtendedDataType::Create(GDT_Float32);
  const auto text = GDALExtendedDataType::CreateString();
  bool ok = true;
  // a 1-D coordinate variable `name` of `values` with its attributes
  auto coordinate = [&](const std::shared_ptr<GDALDimension>& dim, const std::vector<double>& v,
                        const std::vector<std::pair<const char*, std::string>>& attributes) {
    auto a = root->CreateMDArray(dim->GetName(), {dim}, f64);
    if (!a) return ok = false;
    for (const auto& [k, value] : attributes) {
      auto attr = a->CreateAttribute(k, {}, text);
      ok = ok && attr && attr->Write(value.c_str());
    }
    const GUInt64 start[1] = {0};
    const std::size_t count[1] = {v.size()};
    return ok = ok && a->Write(start, count, nullptr, nullptr, f64, v.data());
  };
  auto dt = root->CreateDimension("time", GDAL_DIM_TYPE_TEMPORAL, "", times.size());
  auto dy = root->CreateDimension("y", GDAL_DIM_TYPE_HORIZONTAL_Y, "", ny);
  auto dx = root->CreateDimension("x", GDAL_DIM_TYPE_HORIZONTAL_X, "", nx);
  std::vector<double> xs(nx), ys(ny);
  for (std::size_t c = 0; c < nx; ++c) xs[c] = grid.cell_center(static_cast<int>(c), 0)[0];
  for (std::size_t r = 0; r < ny; ++r) ys[r] = grid.cell_center(0, static_cast<int>(r))[1];
  ok = dt && dy && dx &&
       coordinate(dt, times, {{"units", time_units}, {"axis", "T"}, {"standard_name", "time"}}) &&
       coordinate(dy, ys,
                  {{"units", "m"}, {"axis", "Y"}, {"standard_name", "projection_y_coordinate"}}) &&
       coordinate(dx, xs,
                  {{"units", "m"}, {"axis", "X"}, {"standard_name", "projection_x_coordinate"}});
  auto v = ok ? root->CreateMDArray(variable, {dt, dy, dx}, f32) : nullptr;
  if (v && !units.empty()) {
    auto attr = v->CreateAttribute("units", {}, text);
    ok = attr && attr->Write(units.c_str());
  }
  std::vector<float> all;
  for (const auto& b : bands) all.insert(all.end(), b.begin(), b.end());
  const GUInt64 start[3] = {0, 0, 0};
  const std::size_t count[3] = {bands.size(), ny, nx};
  ok = ok && v && all.size() == bands.size() * nx * ny &&
       v->Write(start, count, nullptr, nullptr, f32, all.data());
  if (!ok) throw Error(ExitCode::cant_create, path + ": cannot write" + gdal_reason());
}

}  // namespace erodem::io
