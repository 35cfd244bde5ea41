// erodem — reading configuration files (see config.hpp).
#include "erodem/io/config.hpp"

#include <toml++/toml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/parameter_rasters.hpp"
#include "erodem/schema.hpp"

namespace erodem {
namespace {

namespace fs = std::filesystem;

/// `path` made absolute against `base_dir` when it is relative and not empty.
std::string resolve_against(const std::string& path, const fs::path& base_dir) {
  if (path.empty()) return path;
  const fs::path p(path);
  if (p.is_absolute()) return path;
  return (base_dir / p).lexically_normal().string();
}

/// The whole file as text; Error(no_input) when it does not exist, Error(io) when it is a
/// folder or cannot be read.
std::string read_config_text(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw Error(ExitCode::io, path + ": a folder, not a config file (give the .toml file in it)");
  if (!fs::is_regular_file(path, ec)) {
    throw Error(ExitCode::no_input, path + ": no such config file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ExitCode::no_input, path + ": cannot open config file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(ExitCode::io, path + ": cannot read config file");
  return text.str();
}

}  // namespace

void resolve_relative_paths(Params& p, const std::string& base_dir) {
  const fs::path base(base_dir.empty() ? "." : base_dir);
  p.dem.path = resolve_against(p.dem.path, base);
  for (const auto& r : parameter_rasters())
    if (std::string* path = r.path(p)) *path = resolve_against(*path, base);
  // the gridded forcing, a raster or a netCDF variable NETCDF:"file.nc":var (its file)
  for (std::string* path : {&p.rain.grids, &p.snow.temperature_grids}) {
    if (auto nc = io::parse_netcdf_name(*path)) {
      nc->file = resolve_against(nc->file, base);
      *path = io::netcdf_name(*nc);
    } else {
      *path = resolve_against(*path, base);
    }
  }
}

Params load_config(const std::string& path) {
  const std::string text = read_config_text(path);
  toml::table table;
  try {
    table = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw Error(ExitCode::config, path + ":" + std::to_string(where.line) + ":" +
                                      std::to_string(where.column) + ": " +
                                      std::string(e.description()));
  }
  Params p = params_from_toml(table, path);
  resolve_relative_paths(p, fs::path(path).parent_path().string());
  return p;
}

}  // namespace erodem
