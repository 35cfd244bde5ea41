// erodem — names, units and descriptions of the fields of MODEL.md.
#pragma once

#include <string>
#include <vector>

namespace erodem {

enum class FieldId {
  bed,
  water_depth,
  sediment,
  velocity_x,
  velocity_y,
  flux_left,
  flux_right,
  flux_top,
  flux_bottom,
  hardness,
  wetness,
  erosion,  ///< derived: initial bed - bed (m); negative = deposition
  manning_n,
  initial_bed,   ///< bed at the start of the run (m); erosion = initial_bed - bed
  bed_residual,  ///< the part of the bed below the precision of `bed` (m; compensated.h)
};

struct FieldInfo {
  FieldId id;
  const char* name;       ///< the name used in configs, files and Python
  const char* units;      ///< UDUNITS string
  const char* long_name;  ///< CF long_name
};

/// All fields, in a fixed order.
const std::vector<FieldInfo>& field_table();
/// The field called `name`; throws erodem::Error(config) listing the names otherwise.
const FieldInfo& field_info(const std::string& name);
const FieldInfo& field_info(FieldId id);

}  // namespace erodem
