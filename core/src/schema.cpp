// erodem — the parameter schema (schema.hpp): lookup of keys in the table of
// schema_table.cpp, did-you-mean suggestions, --set alternatives, the cross-checks between
// keys, and the public API (parsing, --set, validation, dump_toml, parameter docs).
#include "erodem/schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <utility>

#include "schema_kinds.hpp"

namespace erodem {

using namespace schema_detail;

namespace {

const Descriptor* find_descriptor(const std::string& key) {
  for (const Descriptor& d : descriptor_table()) {
    if (d.key == key) return &d;
  }
  return nullptr;
}

/// True when `key` names a table of parameters, e.g. "rain".
bool is_section(const std::string& key) {
  for (const Descriptor& d : descriptor_table()) {
    if (d.key.compare(0, key.size() + 1, key + ".") == 0) return true;
  }
  return false;
}

std::string leaf_of(const std::string& key) {
  const size_t dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1);
  std::vector<size_t> cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, subst});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

Error unknown_key_error(const std::string& source, const std::string& key) {
  const std::string hint = closest_parameter_key(key);
  return config_error_in(
      source, key,
      "unknown parameter" + (hint.empty() ? std::string() : "; did you mean '" + hint + "'?"));
}

/// An unknown table such as [rian]: suggests the closest known table.
Error unknown_table_error(const std::string& source, const std::string& key) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const Descriptor& d : descriptor_table()) {
    const std::string section = d.key.substr(0, d.key.find('.'));
    const size_t distance = edit_distance(key, section);
    if (distance < best_distance) {
      best_distance = distance;
      best = section;
    }
  }
  const bool close = best_distance <= std::max<size_t>(2, key.size() / 4);
  return config_error_in(
      source, key, "unknown table" + (close ? "; did you mean [" + best + "]?" : std::string()));
}

const Descriptor& require_descriptor(const std::string& key, const std::string& source) {
  const Descriptor* d = find_descriptor(key);
  if (!d) throw unknown_key_error(source, key);
  return *d;
}

/// Applies every key of table `t` (whose dotted prefix is `prefix`) to `p`.
void apply_table(Params& p, const toml::table& t, const std::string& prefix,
                 const std::string& source) {
  for (auto&& [k, node] : t) {
    const std::string key =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const Descriptor* d = find_descriptor(key)) {
      d->assign(p, node, Where{source, key});
    } else if (is_section(key)) {
      const toml::table* sub = node.as_table();
      if (!sub) {
        throw config_error_in(
            source, key, "expected a table of parameters [" + key + "], got " + node_text(node));
      }
      apply_table(p, *sub, key, source);
    } else if (node.is_table()) {
      throw unknown_table_error(source, key);
    } else {
      throw unknown_key_error(source, key);
    }
  }
}

/// --set alternatives: setting the first key resets the others, so the last one wins.
const std::vector<std::pair<std::string, std::vector<std::string>>>& alternatives() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> alt{
      {"time.steps", {"time.duration"}},
      {"output.every", {"output.interval"}},
      {"rain.rate", {"rain.series"}},
      {"rain.series", {"rain.rate"}},
      {"dem.path", {"dem.synthetic"}},
      {"dem.synthetic", {"dem.path"}},
      {"initial.water_level", {"initial.water_depth"}},
      {"initial.water_depth", {"initial.water_level"}},
  };
  return alt;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// Parses `text` as one TOML value; nullopt when it is not valid TOML.
std::optional<toml::table> parse_toml_value(const std::string& text) {
  try {
    toml::table doc = toml::parse("value = " + text + "\n");
    if (doc.size() == 1 && doc.contains("value")) return doc;
  } catch (const toml::parse_error&) {
  }
  return std::nullopt;
}

void check_cross_fields(const Params& p, const std::string& source) {
  auto fail = [&](const std::string& key, const std::string& what) {
    return config_error_in(source, key, what);
  };
  if (p.dem.path.empty() && p.dem.synthetic.empty()) {
    throw fail("dem.path", "a DEM is required: give dem.path (a raster file) or dem.synthetic");
  }
  if (!p.dem.path.empty() && !p.dem.synthetic.empty()) {
    throw fail("dem.path", "give dem.path or dem.synthetic, not both");
  }
  if (p.initial.water_level &&
      (p.initial.water_depth.is_raster() || p.initial.water_depth.value != 0.0)) {
    throw fail("initial.water_level", "give initial.water_level or initial.water_depth, not both");
  }
  if (!p.rain.grids.empty() && (p.rain.rate != 0.0 || !p.rain.series.empty()))
    throw fail("rain.grids", "give rain.grids or rain.rate / rain.series, not both");
  if (!p.rain.grid_times.empty() && p.rain.grids.empty())
    throw fail("rain.grid_times", "the times of rain.grids' bands: give rain.grids too");
  if (!p.snow.temperature_grids.empty() &&
      (p.snow.air_temperature != 0.0 || !p.snow.air_temperature_series.empty()))
    throw fail("snow.temperature_grids",
               "give snow.temperature_grids or snow.air_temperature, not both");
  if (!p.snow.temperature_grid_times.empty() && p.snow.temperature_grids.empty())
    throw fail("snow.temperature_grid_times",
               "the times of snow.temperature_grids' bands: give snow.temperature_grids too");
  if (p.rain.rate != 0.0 && !p.rain.series.empty()) {
    throw fail("rain.rate", "give rain.rate or rain.series, not both");
  }
  if (p.output.path.empty()) throw fail("output.path", "must not be empty");
  for (std::size_t k = 0; k < p.inflow.size(); ++k)
    if (p.inflow[k].sediment_concentration > 0 && !p.erosion.enabled)
      throw fail(fmt::format("inflow[{}].sediment_concentration", k),
                 "sediment enters only with erosion.enabled = true (the sediment it carries moves "
                 "and settles with erosion and transport)");
  if (p.boundary.sediment_concentration > 0 && !p.erosion.enabled)
    throw fail("boundary.sediment_concentration",
               "sediment enters only with erosion.enabled = true (as inflow[k]'s: the sediment the "
               "boundary's water carries moves and settles with erosion and transport)");
  if (p.erosion.bedrock_level && p.erosion.soil_thickness.is_raster())
    throw fail("erosion.bedrock_level",
               "give erosion.bedrock_level or a raster erosion.soil_thickness, not both (the "
               "level sets the soil thickness to bed - bedrock_level)");
  const auto& tc = p.terrain_classes;
  const std::pair<const char*, const Params::ClassValues*> classes[] = {{"grass", &tc.grass},
                                                                        {"mud", &tc.mud},
                                                                        {"rock", &tc.rock},
                                                                        {"snow", &tc.snow},
                                                                        {"water", &tc.water}};
  const auto& in = p.infiltration;
  const bool soil_raster = in.suction.is_raster() || in.moisture_deficit.is_raster() ||
                           (in.soil_depth && in.soil_depth->is_raster());
  for (const auto& [name, values] : classes) {
    if (values->any() && !tc.enabled)
      throw fail(fmt::format("terrain_classes.{}", name),
                 "class parameters act only with terrain_classes.enabled = true");
    if (soil_raster && (values->suction || values->moisture_deficit || values->soil_depth))
      throw fail(fmt::format("terrain_classes.{}", name),
                 "its suction, moisture_deficit or soil_depth would combine with a raster of "
                 "infiltration.suction, .moisture_deficit or .soil_depth cell by cell: give the "
                 "soil as rasters or by class, not both");
  }
  const auto& b = p.boundary;
  for (const auto& [key, kind] :
       {std::pair{"boundary.north", b.north}, std::pair{"boundary.south", b.south}})
    if (kind == BoundaryKind::periodic)
      throw fail(key,
                 "\"periodic\" joins the east and west edges only (boundary.periodic_x); the "
                 "north and south edges are closed, open or fixed_level");
  const bool east = b.east == BoundaryKind::periodic, west = b.west == BoundaryKind::periodic;
  if (east != west)
    throw fail(east ? "boundary.west" : "boundary.east",
               fmt::format("must be \"periodic\" too: boundary.{} is, and a periodic edge is "
                           "joined to the opposite one (or set boundary.periodic_x = true)",
                           east ? "east" : "west"));
  if (east && b.periodic_x && !*b.periodic_x)
    throw fail("boundary.periodic_x",
               "is false, but boundary.east and boundary.west are \"periodic\"");
  if (p.flow.order == 2 && p.flow.scheme != FlowScheme::shallow_water)
    throw fail("flow.order",
               "order 2 is the shallow_water scheme's (flow.scheme = \"shallow_water\")");
}

}  // namespace

// ---- public API -------------------------------------------------------------------------

Params params_from_toml(const toml::table& t, const std::string& source_name) {
  Params p;
  apply_table(p, t, "", source_name);
  return p;
}

void apply_setting(Params& p, const std::string& key_text, const std::string& value_text) {
  const std::string source = "--set";
  const std::string key = trim(key_text);
  const Descriptor& d = require_descriptor(key, source);
  const Where where{source, key};
  const std::optional<toml::table> doc = parse_toml_value(value_text);
  const toml::node* node = doc ? doc->get("value") : nullptr;
  const bool wants_text = d.type == "string" || d.type == "choice";
  if (node && !(wants_text && !node->is_string())) {
    d.assign(p, *node, where);
  } else {
    d.assign(p, toml::value<std::string>(trim(value_text)), where);
  }
  for (const auto& [first, others] : alternatives()) {
    if (first != key) continue;
    for (const std::string& other : others) find_descriptor(other)->reset(p);
  }
}

void apply_setting(Params& p, const std::string& key_equals_value) {
  const size_t eq = key_equals_value.find('=');
  if (eq == std::string::npos) {
    throw Error(ExitCode::config, "--set: expected key=value, got '" + key_equals_value + "'");
  }
  apply_setting(p, key_equals_value.substr(0, eq), key_equals_value.substr(eq + 1));
}

void validate(const Params& p, const std::string& source_name) {
  for (const Descriptor& d : descriptor_table()) d.check(p, Where{source_name, d.key});
  check_cross_fields(p, source_name);
}

std::string dump_toml(const Params& p) {
  std::string out = "# erodem configuration, fully resolved (values in SI units)\n";
  std::string section = "-";
  std::vector<const Descriptor*> tables;  // arrays of tables, after every [section]
  for (const Descriptor& d : descriptor_table()) {
    if (d.tables) {
      tables.push_back(&d);
      continue;
    }
    const std::string s = d.key.substr(0, d.key.rfind('.'));  // erosion.soil for its keys
    if (s != section) {
      out += "\n[" + s + "]\n";
      section = s;
    }
    out += "# " + d.doc + "\n";
    const std::optional<std::string> value = d.format(p);
    if (value) {
      out += leaf_of(d.key) + " = " + *value + "\n";
    } else {
      out += "# " + leaf_of(d.key) + " = (not set)\n";
    }
  }
  for (const Descriptor* d : tables) out += d->tables(p);
  return out;
}

std::vector<std::string> parameter_keys() {
  std::vector<std::string> keys;
  for (const Descriptor& d : descriptor_table()) keys.push_back(d.key);
  return keys;
}

std::string parameter_doc(const std::string& key) {
  return require_descriptor(key, "config").doc;
}

ParameterInfo parameter_info(const std::string& key) {
  const Descriptor& d = require_descriptor(key, "config");
  ParameterInfo info;
  info.key = d.key;
  info.type = d.type;
  info.dimension = d.dim;
  info.unit = d.dim == Dimension::dimensionless ? "" : si_unit(d.dim);
  info.accepted = d.accepted;
  const Params defaults;
  if (d.tables) {
    info.default_value = "[]";
  } else {
    info.default_value = d.format(defaults).value_or("(not set)");
  }
  info.doc = d.doc;
  return info;
}

std::string closest_parameter_key(const std::string& key) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  const std::string leaf = leaf_of(key);
  for (const Descriptor& d : descriptor_table()) {
    // the same leaf in another section ("dt" -> "time.dt") ranks before any typo
    const size_t distance = leaf_of(d.key) == leaf ? 0 : edit_distance(key, d.key);
    if (distance < best_distance) {
      best_distance = distance;
      best = d.key;
    }
  }
  const size_t limit = std::max<size_t>(2, key.size() / 4);
  return best_distance <= limit ? best : std::string();
}

bool params_equal(const Params& a, const Params& b) {
  return dump_toml(a) == dump_toml(b);
}

}  // namespace erodem
