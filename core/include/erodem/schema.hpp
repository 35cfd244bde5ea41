// erodem — the one validated parameter schema shared by TOML files, `--set key=value`
// and Python keywords. Every key, default, accepted range and doc line is written once,
// in the descriptor table of schema_table.cpp; everything here is derived from that table.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

#include "erodem/params.hpp"
#include "erodem/units.hpp"

namespace erodem {

/// What the schema knows about one parameter (for --help, docs and error messages).
struct ParameterInfo {
  std::string key;            ///< dotted key, e.g. "rain.rate"
  std::string type;           ///< "number", "integer", "boolean", "string", "choice", ...
  Dimension dimension;        ///< physical dimension of the numbers it holds
  std::string unit;           ///< SI unit of the stored value, e.g. "m/s" ("" if none)
  std::string accepted;       ///< accepted range or choices, e.g. ">= 0", "pipes | local_inertial"
  std::string default_value;  ///< the default as TOML text (from a default Params)
  std::string doc;            ///< one line, with the unit
};

/// Builds a Params from a parsed TOML document, starting from the defaults. Unknown keys
/// and tables, wrong types and out-of-range values throw erodem::Error (ExitCode::config)
/// with a message "<source_name>: '<dotted.key>': ...". Cross-field checks are left to
/// validate(), so that `--set` values can still be applied afterwards.
Params params_from_toml(const toml::table& t, const std::string& source_name);

/// Applies one `--set key=value`: `value_text` is read as a TOML value (numbers, booleans,
/// arrays, quoted strings, inline tables) and, when that fails, as a bare string (so
/// `flow.scheme=pipes` and `rain.rate=20 mm/h` work). Same checks as params_from_toml;
/// errors start with "--set". Setting one of two alternatives clears the other, so the
/// last one wins: time.steps clears time.duration, output.every clears output.interval,
/// rain.rate clears rain.series, dem.path clears dem.synthetic (and the reverse).
void apply_setting(Params& p, const std::string& key, const std::string& value_text);

/// Splits "key=value" at the first '=' and calls apply_setting; a missing '=' is an error.
void apply_setting(Params& p, const std::string& key_equals_value);

/// Checks every parameter's range and the cross-field rules (a DEM source is given, series
/// times increase, output fields are known, ...). Throws erodem::Error (ExitCode::config)
/// with a message starting with `source_name`.
void validate(const Params& p, const std::string& source_name = "config");

/// The fully resolved configuration as TOML text: every key, grouped in tables, each with
/// its doc line as a comment. Parses back through params_from_toml to an identical Params.
/// Unset optional keys are written as comments.
std::string dump_toml(const Params& p);

/// All dotted parameter keys, in schema order.
std::vector<std::string> parameter_keys();

/// The doc line of `key` (with its unit); throws Error(ExitCode::config) for unknown keys.
std::string parameter_doc(const std::string& key);

/// Everything the schema knows about `key`; throws Error(ExitCode::config) for unknown keys.
ParameterInfo parameter_info(const std::string& key);

/// The known key closest to `key` (for "did you mean" hints), or "" when none is close.
std::string closest_parameter_key(const std::string& key);

/// True when the two parameter sets hold identical values (every schema key).
bool params_equal(const Params& a, const Params& b);

/// `s` in double quotes, with `"`, `\` and control characters escaped (\n, \t, \r, \uXXXX):
/// a TOML basic string and a JSON string alike.
std::string quoted_string(const std::string& s);

}  // namespace erodem
