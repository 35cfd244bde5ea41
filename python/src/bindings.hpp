// erodem — pieces of the Python extension module, one add_*_bindings() per area.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <utility>
#include <vector>

#include "erodem/params.hpp"

namespace erodem::python {

/// Parameter settings as the Python layer passes them: (dotted key, value as TOML text).
using Settings = std::vector<std::pair<std::string, std::string>>;

/// Applies `settings` to `p` through the schema (erodem::apply_setting), in order.
void apply_settings(Params& p, const Settings& settings);

/// Exception translation: erodem::Error -> ValueError (config, usage, data),
/// FileNotFoundError (no_input), OSError (cant_create, io), erodem.UnstableError (unstable),
/// RuntimeError (internal); each carries the C++ exit code as `exit_code`.
void add_error_bindings(pybind11::module_& m);
/// parameter_keys(), parameter_info(), default_config().
void add_schema_bindings(pybind11::module_& m);
/// Terrain: a DEM loaded with its `dem.*` settings.
void add_terrain_bindings(pybind11::module_& m);
/// Simulation and ResultWriter.
void add_simulation_bindings(pybind11::module_& m);

}  // namespace erodem::python
