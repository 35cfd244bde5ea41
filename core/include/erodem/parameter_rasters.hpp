// erodem — the parameter rasters: every key of Params that takes a raster on the DEM grid,
// with the Terrain member it loads into and the range of its values. The one list the
// loading, the relative paths, the coarsening and the restart check follow.
#pragma once

#include <string>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

struct ParameterRaster {
  const char* key;  ///< the config key, e.g. "flow.manning_n"
  /// The raster's path in `p` (empty: a uniform value); nullptr where the key is not set.
  std::string* (*path)(Params& p);
  std::vector<double> Terrain::*values;  ///< where load_terrain puts it (SI units)
  double lo, hi;                         ///< the range of its active cells' values
  /// Codes rather than quantities (boundary.raster): whole numbers, never averaged.
  bool categorical = false;
};

/// Every parameter raster, in a fixed order.
const std::vector<ParameterRaster>& parameter_rasters();

/// The raster path of `r` in `p` ("" where it is a uniform value or not set).
std::string parameter_raster_path(const ParameterRaster& r, const Params& p);

}  // namespace erodem
