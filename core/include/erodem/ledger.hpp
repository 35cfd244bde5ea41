// erodem — the conservation ledger (MODEL.md "Conservation ledger"), kept every step in
// double precision whatever the precision of the fields.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace erodem {

/// The volumes (m^3) the processes book every step, each once: a member of StepTally (the
/// step's amount, summed as the process ran) and of Ledger (cumulative), an entry of
/// ledger_entries() and of tally_table() (process.hpp), added in this order. This list is the
/// one place a new tally is declared; the closures below say which budget it enters.
///   X(name, zero_if_absent, doc): `zero_if_absent` for the tallies added after the first
///   result files (the moved volumes of 2026-11-25, the snow melt of 2026-11-26): a restart
///   from a file without them starts them at 0.
#define ERODEM_TALLIES(X)                                                                  \
  X(boundary_out, false, "net water out through open / fixed-level ghosts")                \
  X(evaporated, false, "water evaporated")                                                 \
  X(clipped, false, "water added to lift rounding-level negative depths")                  \
  X(sediment_out, false, "sediment carried out through the boundary")                      \
  X(transport_change, false,                                                               \
    "change of sum(s * area) by transport (non-zero only for the semi-Lagrangian scheme)") \
  X(water_exchanged, true, "water the cells gave through their faces")                     \
  X(eroded, true, "bed taken into suspension")                                             \
  X(deposited, true, "suspended sediment laid down on the bed")                            \
  X(sediment_exchanged, true, "sediment the cells gave through their faces")               \
  X(thermal_moved, true, "bed moved between cells by slope collapse")                      \
  X(snow_melted, true, "snow melted into the pack's liquid water (water equivalent)")      \
  X(snowfall, true, "precipitation fallen on the snow pack as snow (water equivalent)")    \
  X(rain_on_snow, true, "rain the snow pack's liquid water took from the depth")           \
  X(snow_runoff, true, "liquid water of the snow pack released into the depth")            \
  X(eroded_bedrock, true, "solid taken into suspension from the bedrock (part of eroded)") \
  X(bed_bulking, true,                                                                     \
    "bed volume lowered minus solid moved into suspension: pores opened (closed by "       \
    "deposits), and the morphological acceleration's extra")                               \
  X(infiltrated, true, "water infiltrated into the soil")                                  \
  X(soil_drained, true, "water drained from the soil store as its capacity recovers")

/// The volumes (m^3) that crossed the model's boundaries or moved inside it during the
/// processes run so far in one step (ERODEM_TALLIES).
struct StepTally {
#define ERODEM_TALLY_MEMBER(name, zero_if_absent, doc) double name = 0.0;
  ERODEM_TALLIES(ERODEM_TALLY_MEMBER)
#undef ERODEM_TALLY_MEMBER
};

struct Ledger {
  // water (m^3)
  double water_initial = 0.0;
  double water = 0.0;
  double rain = 0.0;    ///< cumulative rain volume
  double inflow = 0.0;  ///< cumulative point/line inflow volume
  /// cumulative solid sediment the inflows brought (inflow.sediment_concentration)
  double sediment_inflow = 0.0;
  // material: bed + suspended sediment (m^3)
  double material_initial = 0.0;
  double material = 0.0;
  // the cumulative tallies (ERODEM_TALLIES)
#define ERODEM_TALLY_MEMBER(name, zero_if_absent, doc) double name = 0.0;
  ERODEM_TALLIES(ERODEM_TALLY_MEMBER)
#undef ERODEM_TALLY_MEMBER

  /// The relative closures' floor: the closure of a run in which nothing moved is judged
  /// against this fraction of the volume on the grid (the rounding of a double sum).
  static constexpr double kVolumeEpsilon = std::numeric_limits<double>::epsilon();

  /// V(t) - V(0) - rain - inflow + out + evaporated - clipped + snowfall + rain on snow - snow
  /// runoff + infiltrated: 0 up to rounding (m^3). The snow pack is outside V: what it takes
  /// from the depth (snowfall, rain on snow) and gives back (snow runoff) cross its boundary;
  /// the melt moves water inside the pack (snow_storage_closure_error).
  double closure_error() const {
    return water - water_initial - rain - inflow + boundary_out + evaporated - clipped + snowfall +
           rain_on_snow - snow_runoff + infiltrated;
  }
  /// What moved of the water (m^3): max(rain + inflow + |boundary out| + evaporated + snow
  /// runoff + snowfall + rain on snow + infiltrated, water exchanged between cells,
  /// kVolumeEpsilon * water on the grid).
  double water_moved() const {
    return std::max({rain + inflow + std::abs(boundary_out) + evaporated + snow_runoff + snowfall +
                         rain_on_snow + infiltrated,
                     water_exchanged,
                     kVolumeEpsilon * std::max(std::abs(water_initial), std::abs(water))});
  }
  /// Closure error relative to water_moved().
  double relative_closure_error() const {
    const double scale = water_moved();
    return scale > 0 ? closure_error() / scale : 0.0;
  }
  /// M(t) - M(0) - sediment inflow + sediment out - transport change + bed bulking: 0 up to
  /// rounding (m^3).
  /// M is the bed's volume plus the suspended solid: erosion from a porous layer lowers the
  /// bed by more than the solid it lifts (bed_bulking; 0 with Mei's law).
  double material_closure_error() const {
    return material - material_initial - sediment_inflow + sediment_out - transport_change +
           bed_bulking;
  }
  /// What moved of the material (m^3): max(eroded + deposited + sediment out + in, sediment and
  /// bed exchanged between cells, kVolumeEpsilon * material on the grid).
  double material_moved() const {
    return std::max({eroded + deposited + std::abs(sediment_out) + sediment_inflow,
                     sediment_exchanged + thermal_moved + std::abs(transport_change),
                     kVolumeEpsilon * std::max(std::abs(material_initial), std::abs(material))});
  }
  /// Material closure error relative to material_moved().
  double relative_material_closure_error() const {
    const double scale = material_moved();
    return scale > 0 ? material_closure_error() / scale : 0.0;
  }

  /// A human-readable table.
  std::string format() const;
};

/// One kept entry of the ledger (m^3): its name (a key of the Python ledger dict,
/// `ledger_<name>` in an HDF5 file's restart/) and its member.
struct LedgerEntry {
  const char* name;
  double Ledger::*member;
  /// Absent from files written before it existed: a restart from such a file starts it at 0
  /// (the moved volumes, 2026-11-25; the snow melt, 2026-11-26).
  bool zero_if_absent = false;
};

/// Every kept entry of the ledger: the volumes on the grid, rain and inflow, then the tallies
/// in the order of ERODEM_TALLIES (the derived closure errors are not kept).
const std::vector<LedgerEntry>& ledger_entries();

}  // namespace erodem
