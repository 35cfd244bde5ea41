// erodem — the conservation ledger (MODEL.md "Conservation ledger"), kept every step in
// double precision whatever the precision of the fields.
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace erodem {

/// The volumes (m^3) the processes book every step, each once: a member of StepTally (the
/// step's amount, summed as the process ran) and of Ledger (cumulative), an entry of
/// ledger_entries() and of tally_table() (process.hpp), added in this order. This list is the
/// one place a new tally is declared; the closures below say which budget it enters.
///   X(name, moved, doc): `moved` is true for the volumes moved inside the domain (the
///   closures' scales; absent in files before 2026-11-25).
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
  X(thermal_moved, true, "bed moved between cells by slope collapse")

/// The volumes (m^3) that crossed the model's boundaries or moved inside it during the
/// processes run so far in one step (ERODEM_TALLIES).
struct StepTally {
#define ERODEM_TALLY_MEMBER(name, moved, doc) double name = 0.0;
  ERODEM_TALLIES(ERODEM_TALLY_MEMBER)
#undef ERODEM_TALLY_MEMBER
};

struct Ledger {
  // water (m^3)
  double water_initial = 0.0;
  double water = 0.0;
  double rain = 0.0;    ///< cumulative rain volume
  double inflow = 0.0;  ///< cumulative point/line inflow volume
  // material: bed + suspended sediment (m^3)
  double material_initial = 0.0;
  double material = 0.0;
  // the cumulative tallies (ERODEM_TALLIES)
#define ERODEM_TALLY_MEMBER(name, moved, doc) double name = 0.0;
  ERODEM_TALLIES(ERODEM_TALLY_MEMBER)
#undef ERODEM_TALLY_MEMBER

  /// The relative closures' floor: the closure of a run in which nothing moved is judged
  /// against this fraction of the volume on the grid (the rounding of a double sum).
  static constexpr double kVolumeEpsilon = std::numeric_limits<double>::epsilon();

  /// V(t) - V(0) - rain - inflow + out + evaporated - clipped: 0 up to rounding (m^3).
  double closure_error() const {
    return water - water_initial - rain - inflow + boundary_out + evaporated - clipped;
  }
  /// What moved of the water (m^3): max(rain + inflow + |boundary out| + evaporated, water
  /// exchanged between cells, kVolumeEpsilon * water on the grid).
  double water_moved() const;
  /// Closure error relative to water_moved().
  double relative_closure_error() const;
  /// M(t) - M(0) + sediment out - transport change: 0 up to rounding (m^3).
  double material_closure_error() const {
    return material - material_initial + sediment_out - transport_change;
  }
  /// What moved of the material (m^3): max(eroded + deposited + sediment out, sediment and
  /// bed exchanged between cells, kVolumeEpsilon * material on the grid).
  double material_moved() const;
  /// Material closure error relative to material_moved().
  double relative_material_closure_error() const;

  /// A human-readable table.
  std::string format() const;
};

/// One kept entry of the ledger (m^3): its name (a key of the Python ledger dict,
/// `ledger_<name>` in an HDF5 file's restart/) and its member.
struct LedgerEntry {
  const char* name;
  double Ledger::*member;
  bool moved = false;  ///< one of the moved volumes (absent in files before 2026-11-25)
};

/// Every kept entry of the ledger: the volumes on the grid, rain and inflow, then the tallies
/// in the order of ERODEM_TALLIES (the derived closure errors are not kept).
const std::vector<LedgerEntry>& ledger_entries();

}  // namespace erodem
