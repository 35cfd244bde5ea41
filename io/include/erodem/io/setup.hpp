// erodem — from a validated Params to a ready Simulation: reads the DEM (or generates a
// synthetic one) and the parameter rasters, then builds the backend.
#pragma once

#include <string>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"
#include "erodem/simulation.hpp"

namespace erodem::io {

/// The DEM (file or synthetic) and every raster parameter of `p` on its grid.
Terrain load_terrain(const Params& p);

/// A simulation of `p` on backend `backend` ("auto", "cpu", ...).
Simulation make_simulation(const Params& p, const std::string& backend);

}  // namespace erodem::io
