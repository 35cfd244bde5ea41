// erodem — the terrain object of the Python layer: a DEM loaded with its `dem.*` settings.
#pragma once

#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem::python {

/// What erodem.read_dem() returns (wrapped by erodem.DEM): the terrain as io::load_terrain
/// builds it from `dem` (window, resample, z_scale, ... applied), and those settings, so a
/// Simulation built on it uses exactly this terrain. DEM.from_array() builds one from values
/// in memory (`in_memory`; `dem` then holds only its name as dem.path).
struct PyTerrain {
  Params::Dem dem;  ///< the validated [dem] settings it was read with
  Terrain terrain;  ///< bed (m), mask, grid (per-row dx, dy, area in m, m^2), georeferencing
  /// Built from values in memory (DEM.from_array), not read from a file: there is no file
  /// to read again, so parameter rasters cannot be read on its grid.
  bool in_memory = false;
};

}  // namespace erodem::python
