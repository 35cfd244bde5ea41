#include "erodem/fields.hpp"

#include "erodem/error.hpp"

namespace erodem {

const std::vector<FieldInfo>& field_table() {
  static const std::vector<FieldInfo> table{
      {FieldId::bed, "bed", "m", "bed (terrain) elevation"},
      {FieldId::water_depth, "water_depth", "m", "water column depth"},
      {FieldId::sediment, "sediment", "m", "suspended sediment as an equivalent bed layer"},
      {FieldId::velocity_x, "velocity_x", "m s-1", "depth-averaged eastward velocity"},
      {FieldId::velocity_y, "velocity_y", "m s-1", "depth-averaged northward velocity"},
      {FieldId::flux_left, "flux_left", "m3 s-1", "outflow through the west face"},
      {FieldId::flux_right, "flux_right", "m3 s-1", "outflow through the east face"},
      {FieldId::flux_top, "flux_top", "m3 s-1", "outflow through the north face"},
      {FieldId::flux_bottom, "flux_bottom", "m3 s-1", "outflow through the south face"},
      {FieldId::hardness, "hardness", "1", "erodibility multiplier"},
      {FieldId::wetness, "wetness", "m", "running mean of water depth"},
      {FieldId::erosion, "erosion", "m", "cumulative net erosion (negative: deposition)"},
      {FieldId::manning_n, "manning_n", "s m-1/3", "Manning roughness coefficient"},
      {FieldId::initial_bed, "initial_bed", "m", "bed elevation at the start of the run"},
      {FieldId::bed_residual, "bed_residual", "m",
       "bed elevation below the precision of bed (the bed is bed + bed_residual)"},
  };
  return table;
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
