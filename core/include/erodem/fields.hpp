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
  /// Kept from one step to the next: stored in a result file's restart/ group and restored
  /// from it (state_fields()); everything else is derived from the terrain and the parameters
  /// or recomputed within a step.
  bool state = false;
  /// A choice of output.fields (written in each snapshot when chosen).
  bool output = false;
  /// Absent from the restart state of files written before it existed: such a file restarts
  /// with 0 in it (the bed residual, 2026-11-25).
  bool restart_zero_if_absent = false;
};

/// All fields, in a fixed order: the order of state_fields() and of output_field_names().
const std::vector<FieldInfo>& field_table();
/// The fields a backend keeps from one step to the next (FieldInfo::state), in table order.
const std::vector<FieldId>& state_fields();
/// The names output.fields accepts (FieldInfo::output), in table order.
const std::vector<std::string>& output_field_names();
/// The field called `name`; throws erodem::Error(config) listing the names otherwise.
const FieldInfo& field_info(const std::string& name);
const FieldInfo& field_info(FieldId id);

}  // namespace erodem
