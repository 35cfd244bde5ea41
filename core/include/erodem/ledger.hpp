// erodem — the conservation ledger (MODEL.md "Conservation ledger"), kept every step in
// double precision whatever the precision of the fields.
#pragma once

#include <array>
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

  /// V(t) - V(0) - rain - inflow + out + evaporated - clipped: 0 up to rounding (m^3).
  double closure_error() const {
    return water - water_initial - rain - inflow + boundary_out + evaporated - clipped;
  }
  /// Closure error relative to the largest water volume that entered the books.
  double relative_closure_error() const;
  /// M(t) - M(0) + sediment out - transport change: 0 up to rounding (m^3).
  double material_closure_error() const {
    return material - material_initial + sediment_out - transport_change;
  }
  double relative_material_closure_error() const;

  /// A human-readable table.
  std::string format() const;
};

/// One kept entry of the ledger (m^3): its name (a key of the Python ledger dict,
/// `ledger_<name>` in an HDF5 file's restart/) and its member.
struct LedgerEntry {
  const char* name;
  double Ledger::*member;
};

/// Every kept entry of the ledger, in the order of the structure (the derived closure errors
/// are not kept).
const std::array<LedgerEntry, 11>& ledger_entries();

}  // namespace erodem
