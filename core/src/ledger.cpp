#include "erodem/ledger.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace erodem {

const std::vector<LedgerEntry>& ledger_entries() {
  static const std::vector<LedgerEntry> table{{"water_initial", &Ledger::water_initial},
                                              {"water", &Ledger::water},
                                              {"rain", &Ledger::rain},
                                              {"inflow", &Ledger::inflow},
                                              {"material_initial", &Ledger::material_initial},
                                              {"material", &Ledger::material},
#define ERODEM_TALLY_ENTRY(name, moved, doc) {#name, &Ledger::name, moved},
                                              ERODEM_TALLIES(ERODEM_TALLY_ENTRY)
#undef ERODEM_TALLY_ENTRY
  };
  return table;
}

double Ledger::water_moved() const {
  return std::max({rain + inflow + std::abs(boundary_out) + evaporated, water_exchanged,
                   kVolumeEpsilon * std::max(std::abs(water_initial), std::abs(water))});
}

double Ledger::relative_closure_error() const {
  const double scale = water_moved();
  return scale > 0 ? closure_error() / scale : 0.0;
}

double Ledger::material_moved() const {
  return std::max({eroded + deposited + std::abs(sediment_out),
                   sediment_exchanged + thermal_moved + std::abs(transport_change),
                   kVolumeEpsilon * std::max(std::abs(material_initial), std::abs(material))});
}

double Ledger::relative_material_closure_error() const {
  const double scale = material_moved();
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
  s += fmt::format("           exchanged between cells {:>14.9e}\n", water_exchanged);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e} of {:.9e} moved\n",
                   closure_error(), relative_closure_error(), water_moved());
  s += fmt::format("  material initial {:>18.9e}   now {:>18.9e}\n", material_initial, material);
  s += fmt::format("           sediment out {:>13.9e}   transport change {:>10.3e}\n", sediment_out,
                   transport_change);
  s += fmt::format("           eroded  {:>18.9e}   deposited {:>12.9e}\n", eroded, deposited);
  s += fmt::format("           exchanged: sediment {:>14.9e}   thermal {:>14.9e}\n",
                   sediment_exchanged, thermal_moved);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e} of {:.9e} moved\n",
                   material_closure_error(), relative_material_closure_error(), material_moved());
  return s;
}

}  // namespace erodem
