#include "erodem/ledger.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace erodem {

const std::array<LedgerEntry, 11>& ledger_entries() {
  static const std::array<LedgerEntry, 11> table{{
      {"water_initial", &Ledger::water_initial},
      {"water", &Ledger::water},
      {"rain", &Ledger::rain},
      {"inflow", &Ledger::inflow},
      {"boundary_out", &Ledger::boundary_out},
      {"evaporated", &Ledger::evaporated},
      {"clipped", &Ledger::clipped},
      {"material_initial", &Ledger::material_initial},
      {"material", &Ledger::material},
      {"sediment_out", &Ledger::sediment_out},
      {"transport_change", &Ledger::transport_change},
  }};
  return table;
}

double Ledger::relative_closure_error() const {
  const double scale = std::max({std::abs(water_initial), std::abs(water), rain + inflow,
                                 std::abs(boundary_out) + evaporated});
  return scale > 0 ? closure_error() / scale : 0.0;
}

double Ledger::relative_material_closure_error() const {
  const double scale = std::max(std::abs(material_initial), std::abs(material));
  return scale > 0 ? material_closure_error() / scale : 0.0;
}

std::string Ledger::format() const {
  std::string s;
  s += "mass ledger (m^3)\n";
  s += fmt::format("  water    initial {:>18.9e}   now {:>18.9e}\n", water_initial, water);
  s += fmt::format("           rain    {:>18.9e}   inflow {:>15.9e}\n", rain, inflow);
  s += fmt::format("           out     {:>18.9e}   evaporated {:>11.9e}\n", boundary_out,
                   evaporated);
  s += fmt::format("           clipped {:>18.9e}\n", clipped);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e}\n", closure_error(),
                   relative_closure_error());
  s += fmt::format("  material initial {:>18.9e}   now {:>18.9e}\n", material_initial, material);
  s += fmt::format("           sediment out {:>13.9e}   transport change {:>10.3e}\n", sediment_out,
                   transport_change);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e}\n", material_closure_error(),
                   relative_material_closure_error());
  return s;
}

}  // namespace erodem
