#include "erodem/fields.hpp"

#include "erodem/error.hpp"

namespace erodem {

const std::vector<FieldInfo>& field_table() {
  // name, units, long name; state (restart), output choice, restarts with 0 when absent
  static const std::vector<FieldInfo> table{
      {FieldId::bed, "bed", "m", "bed (terrain) elevation", true, true},
      {FieldId::water_depth, "water_depth", "m", "water column depth", true, true},
      {FieldId::sediment, "sediment", "m", "suspended sediment as an equivalent bed layer", true,
       true},
      {FieldId::velocity_x, "velocity_x", "m s-1", "depth-averaged eastward velocity", true, true},
      {FieldId::velocity_y, "velocity_y", "m s-1", "depth-averaged northward velocity", true, true},
      {FieldId::flux_left, "flux_left", "m3 s-1", "outflow through the west face", true, true},
      {FieldId::flux_right, "flux_right", "m3 s-1", "outflow through the east face", true, true},
      {FieldId::flux_top, "flux_top", "m3 s-1", "outflow through the north face", true, true},
      {FieldId::flux_bottom, "flux_bottom", "m3 s-1", "outflow through the south face", true, true},
      {FieldId::hardness, "hardness", "1", "erodibility multiplier", false, true},
      {FieldId::wetness, "wetness", "m", "running mean of water depth", true, true},
      {FieldId::erosion, "erosion", "m", "cumulative net erosion (negative: deposition)", false,
       true},
      {FieldId::manning_n, "manning_n", "s m-1/3", "Manning roughness coefficient"},
      {FieldId::initial_bed, "initial_bed", "m", "bed elevation at the start of the run", true},
      {FieldId::bed_residual, "bed_residual", "m",
       "bed elevation below the precision of bed (the bed is bed + bed_residual)", true, false,
       true},
  };
  return table;
}

const std::vector<FieldId>& state_fields() {
  static const std::vector<FieldId> ids = [] {
    std::vector<FieldId> v;
    for (const auto& f : field_table())
      if (f.state) v.push_back(f.id);
    return v;
  }();
  return ids;
}

const std::vector<std::string>& output_field_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& f : field_table())
      if (f.output) v.emplace_back(f.name);
    return v;
  }();
  return names;
}

const FieldInfo& field_info(const std::string& name) {
  std::string names;
  for (const auto& f : field_table()) {
    if (name == f.name) return f;
    names += names.empty() ? f.name : std::string(", ") + f.name;
  }
  throw Error(ExitCode::config, "unknown field '" + name + "' (known: " + names + ")");
}

const FieldInfo& field_info(FieldId id) {
  for (const auto& f : field_table())
    if (f.id == id) return f;
  throw Error(ExitCode::internal, "field id without a table entry");
}

}  // namespace erodem
