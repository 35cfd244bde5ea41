#include "erodem/parameter_rasters.hpp"

#include <cmath>

namespace erodem {

const std::vector<ParameterRaster>& parameter_rasters() {
  const double inf = HUGE_VAL;
  static const std::vector<ParameterRaster> table{
      {"initial.water_depth", [](Params& p) { return &p.initial.water_depth.path; },
       &Terrain::water_depth, 0.0, inf},
      {"flow.manning_n", [](Params& p) { return &p.flow.manning_n.path; }, &Terrain::manning_n, 0.0,
       1.0},
      {"erosion.hardness", [](Params& p) { return &p.erosion.hardness.path; }, &Terrain::hardness,
       0.0, 1.0},
      {"erosion.soil_thickness", [](Params& p) { return &p.erosion.soil_thickness.path; },
       &Terrain::soil_thickness, 0.0, inf},
      {"rain.raster", [](Params& p) { return &p.rain.raster; }, &Terrain::rain_factor, 0.0, inf},
      {"infiltration.ksat", [](Params& p) { return &p.infiltration.ksat.path; }, &Terrain::ksat,
       0.0, inf},
      {"infiltration.suction", [](Params& p) { return &p.infiltration.suction.path; },
       &Terrain::suction, 0.0, inf},
      {"infiltration.moisture_deficit",
       [](Params& p) { return &p.infiltration.moisture_deficit.path; }, &Terrain::moisture_deficit,
       0.0, 1.0},
      {"infiltration.soil_depth",
       [](Params& p) {
         return p.infiltration.soil_depth ? &p.infiltration.soil_depth->path : nullptr;
       },
       &Terrain::soil_depth, 0.0, inf},
      {"boundary.raster", [](Params& p) { return &p.boundary.raster; }, &Terrain::boundary_code,
       0.0, 3.0, true},
      {"snow.initial", [](Params& p) { return &p.snow.initial.path; }, &Terrain::snow_initial, 0.0,
       inf},
  };
  return table;
}

std::string parameter_raster_path(const ParameterRaster& r, const Params& p) {
  // the accessors only take an address: reading through them leaves `p` as it is
  const std::string* path = r.path(const_cast<Params&>(p));
  return path ? *path : std::string();
}

}  // namespace erodem
