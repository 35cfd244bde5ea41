#include "erodem/ledger.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

namespace erodem {

const std::vector<LedgerEntry>& ledger_entries() {
  static const std::vector<LedgerEntry> table{{"water_initial", &Ledger::water_initial},
                                              {"water", &Ledger::water},
                                              {"rain", &Ledger::rain},
                                              {"inflow", &Ledger::inflow},
                                              {"sediment_inflow", &Ledger::sediment_inflow, true},
                                              {"material_initial", &Ledger::material_initial},
                                              {"material", &Ledger::material},
#define ERODEM_TALLY_ENTRY(name, zero_if_absent, doc) {#name, &Ledger::name, zero_if_absent},
                                              ERODEM_TALLIES(ERODEM_TALLY_ENTRY)
#undef ERODEM_TALLY_ENTRY
  };
  return table;
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
  // the tallies this table does not name (ERODEM_TALLIES grows without editing it)
  static const std::set<std::string> named{"water_initial",
                                           "water",
                                           "rain",
                                           "inflow",
                                           "boundary_out",
                                           "evaporated",
                                           "sediment_inflow",
                                           "clipped",
                                           "water_exchanged",
                                           "material_initial",
                                           "material",
                                           "sediment_out",
                                           "transport_change",
                                           "eroded",
                                           "deposited",
                                           "sediment_exchanged",
                                           "thermal_moved",
                                           "eroded_bedrock",
                                           "bed_bulking"};
  for (const auto& e : ledger_entries())
    if (!named.count(e.name))
      s += fmt::format("           {:<24} {:>14.9e}\n", e.name, this->*e.member);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e} of {:.9e} moved\n",
                   closure_error(), relative_closure_error(), water_moved());
  s += fmt::format("  material initial {:>18.9e}   now {:>18.9e}\n", material_initial, material);
  s += fmt::format("           sediment out {:>13.9e}   transport change {:>10.3e}\n", sediment_out,
                   transport_change);
  if (sediment_inflow != 0)
    s += fmt::format("           sediment in  {:>13.9e}   (inflows)\n", sediment_inflow);
  s += fmt::format("           eroded  {:>18.9e}   deposited {:>12.9e}\n", eroded, deposited);
  s += fmt::format("           exchanged: sediment {:>14.9e}   thermal {:>14.9e}\n",
                   sediment_exchanged, thermal_moved);
  if (eroded_bedrock != 0 || bed_bulking != 0)  // the physical erosion law (solid volumes)
    s += fmt::format("           from bedrock {:>13.9e}   bed bulking {:>15.9e}\n", eroded_bedrock,
                     bed_bulking);
  s += fmt::format("           closure {:>18.9e}   relative {:>13.3e} of {:.9e} moved\n",
                   material_closure_error(), relative_material_closure_error(), material_moved());
  return s;
}

}  // namespace erodem
