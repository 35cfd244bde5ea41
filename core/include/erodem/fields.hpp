// erodem — names, units and descriptions of the fields of MODEL.md.
#pragma once

#include <string>
#include <vector>

namespace erodem {

/// What a field is (ERODEM_FIELDS' flags).
enum FieldFlag : unsigned {
  kStateField = 1u << 0,    ///< FieldInfo::state
  kOutputField = 1u << 1,   ///< FieldInfo::output
  kRestartZero = 1u << 2,   ///< FieldInfo::restart_zero_if_absent
  kTwinField = 1u << 3,     ///< FieldInfo::twin
  kDerivedField = 1u << 4,  ///< FieldInfo::derived
};

/// Every field of MODEL.md, in a fixed order (the order of state_fields() and of
/// output_field_names()), each once: X(id, units, long_name, flags). The id is the name used
/// in configs, files and Python; units are UDUNITS strings; long_name is the CF long_name. This
/// list is the one place a new field is declared: FieldId, field_table() and the backends'
/// storage (a field no hand-written process binds gets a zeroed array) follow from it.
#define ERODEM_FIELDS(X)                                                                           \
  X(bed, "m", "bed (terrain) elevation", kStateField | kOutputField | kTwinField)                  \
  X(water_depth, "m", "water column depth", kStateField | kOutputField | kTwinField)               \
  X(sediment, "m", "suspended sediment, solid volume per unit area",                               \
    kStateField | kOutputField | kTwinField)                                                       \
  X(velocity_x, "m s-1", "depth-averaged eastward velocity", kStateField | kOutputField)           \
  X(velocity_y, "m s-1", "depth-averaged northward velocity", kStateField | kOutputField)          \
  X(flux_left, "m3 s-1", "outflow through the west face", kStateField | kOutputField)              \
  X(flux_right, "m3 s-1", "outflow through the east face", kStateField | kOutputField)             \
  X(flux_top, "m3 s-1", "outflow through the north face", kStateField | kOutputField)              \
  X(flux_bottom, "m3 s-1", "outflow through the south face", kStateField | kOutputField)           \
  X(hardness, "1", "erodibility multiplier", kOutputField)                                         \
  X(wetness, "m", "running mean of water depth", kStateField | kOutputField)                       \
  /* derived: initial bed - bed (m); negative = deposition */                                      \
  X(erosion, "m", "cumulative net erosion (negative: deposition)", kOutputField | kDerivedField)   \
  X(manning_n, "s m-1/3", "Manning roughness coefficient", 0u)                                     \
  /* rain.raster's multiplier (1), or with rain.grids the step's rain rate (m/s) */                \
  X(rain_factor, "1", "rain multiplier", 0u)                                                       \
  /* the bed at the start of the run (m); erosion = initial_bed - bed */                           \
  X(initial_bed, "m", "bed elevation at the start of the run", kStateField)                        \
  /* the part of the bed below the precision of `bed` (m; compensated.h) */                        \
  X(bed_residual, "m", "bed elevation below the precision of bed (the bed is bed + bed_residual)", \
    kStateField | kRestartZero)                                                                    \
  /* the snow pack (snow.h); files before 2026-11-26 restart without snow */                       \
  X(snow, "m", "snow water equivalent", kStateField | kOutputField | kRestartZero)                 \
  /* the liquid water the pack holds (snow.h); files before 2026-11-26's snowfall restart dry */   \
  X(snow_liquid, "m", "liquid water held in the snow pack",                                        \
    kStateField | kOutputField | kRestartZero)                                                     \
  /* the snow pack's sliding: what a cell gives per metre of its neighbours' excess drop */        \
  X(snow_slide_share, "1", "snow sliding: pack given per metre of excess drop", 0u)                \
  /* snow.temperature_grids: the air temperature of the step's midpoint at each cell */            \
  X(air_temperature, "degC", "air temperature (snow.temperature_grids)", 0u)                       \
  /* the shallow-water scheme's state (shallow_water.h); 0 with the other schemes */               \
  X(momentum_x, "m2 s-1", "depth-integrated eastward discharge per unit width",                    \
    kStateField | kOutputField | kRestartZero | kTwinField)                                        \
  X(momentum_y, "m2 s-1", "depth-integrated northward discharge per unit width",                   \
    kStateField | kOutputField | kRestartZero | kTwinField)                                        \
  /* derived: the bed shear stress of the depth, velocities and Manning n (erosion.h) */           \
  X(shear_stress, "Pa", "bed shear stress", kOutputField | kDerivedField)                          \
  /* the loose layer over the bedrock (erosion.law = "physical"; 0 with Mei's law) */              \
  X(soil_thickness, "m", "thickness of the loose layer (soil) over the bedrock",                   \
    kStateField | kOutputField | kRestartZero)                                                     \
  /* Green-Ampt infiltration (infiltration.h): the depth the soil holds, and the soil */           \
  X(infiltrated, "m", "water infiltrated into the soil store (Green-Ampt F)",                      \
    kStateField | kOutputField | kRestartZero)                                                     \
  X(infiltration_ksat, "m s-1", "saturated hydraulic conductivity", 0u)                            \
  X(infiltration_suction_deficit, "m", "wetting-front suction head times moisture deficit", 0u)    \
  X(infiltration_store, "m", "largest depth the soil store holds", 0u)                             \
  /* terrain classes (terrain_class.h): the class codes 0 grass, 1 mud, 2 rock, 3 snow, */         \
  /* 4 water; and the talus slope the class tables give slope collapse */                          \
  X(terrain_class, "1", "terrain class (0 grass, 1 mud, 2 rock, 3 snow, 4 water)",                 \
    kStateField | kOutputField | kRestartZero)                                                     \
  X(talus_slope, "1", "tangent of the talus angle", 0u)

enum class FieldId {
#define ERODEM_FIELD_ID(id, units, long_name, flags) id,
  ERODEM_FIELDS(ERODEM_FIELD_ID)
#undef ERODEM_FIELD_ID
};

/// The number of fields (FieldId values 0 .. kFieldCount - 1).
constexpr int kFieldCount = 0
#define ERODEM_FIELD_COUNT(id, units, long_name, flags) +1
    ERODEM_FIELDS(ERODEM_FIELD_COUNT)
#undef ERODEM_FIELD_COUNT
    ;

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
  /// Kept in two buffers by the backends (a sweep reads the old values of the neighbours
  /// while it writes the new ones): set_field() writes both.
  bool twin = false;
  /// Computed from other fields when read (the erosion); no storage, cannot be set.
  bool derived = false;
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
