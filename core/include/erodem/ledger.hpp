// erodem — the conservation ledger (MODEL.md "Conservation ledger"), kept every step in
// double precision whatever the precision of the fields.
#pragma once

#include <array>
#include <limits>
#include <string>

namespace erodem {

struct Ledger {
  // water (m^3)
  double water_initial = 0.0;
  double water = 0.0;
  double rain = 0.0;          ///< cumulative rain volume
  double inflow = 0.0;        ///< cumulative point/line inflow volume
  double boundary_out = 0.0;  ///< cumulative net outflow through the boundary
  double evaporated = 0.0;    ///< cumulative evaporated volume
  double clipped = 0.0;       ///< cumulative volume added when clipping rounding-level negatives
  // material: bed + suspended sediment (m^3)
  double material_initial = 0.0;
  double material = 0.0;
  double sediment_out = 0.0;      ///< cumulative sediment carried out through the boundary
  double transport_change = 0.0;  ///< cumulative change of sediment volume by transport
                                  ///< (non-zero only for the semi-Lagrangian scheme)
  // what moved inside the domain, cumulative (m^3): the scales of the relative closures
  double water_exchanged = 0.0;     ///< water the cells gave through their faces
  double eroded = 0.0;              ///< bed taken into suspension
  double deposited = 0.0;           ///< suspended sediment laid down on the bed
  double sediment_exchanged = 0.0;  ///< sediment the cells gave through their faces
  double thermal_moved = 0.0;       ///< bed moved between cells by slope collapse

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

/// Every kept entry of the ledger, in the order of the structure (the derived closure errors
/// are not kept).
const std::array<LedgerEntry, 16>& ledger_entries();

}  // namespace erodem
