// erodem — reading configuration files (TOML) into a Params through the schema.
#pragma once

#include <string>

#include "erodem/params.hpp"

namespace erodem {

/// Reads the TOML config file at `path` into a Params (defaults for keys not given).
/// Relative raster paths inside it (dem.path, initial.water_depth, flow.manning_n,
/// erosion.hardness, rain.raster) are resolved against the config file's directory;
/// output.path stays relative to the working directory.
/// Errors: a missing file -> Error(ExitCode::no_input, "<path>: no such config file"); a
/// folder -> Error(ExitCode::io, "<path>: a folder, not a config file ...");
/// a TOML syntax error -> Error(ExitCode::config, "<path>:<line>:<col>: <message>");
/// unknown keys and bad values -> Error(ExitCode::config, "<path>: '<key>': ...").
/// Cross-field checks are not done here: call erodem::validate() after any --set.
Params load_config(const std::string& path);

/// Resolves the relative raster paths of `p` against `base_dir` (see load_config).
void resolve_relative_paths(Params& p, const std::string& base_dir);

}  // namespace erodem
