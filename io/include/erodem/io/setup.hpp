// erodem — from a validated Params to a ready Simulation: reads the DEM (or generates a
// synthetic one) and the parameter rasters, then builds the backend.
#pragma once

#include <string>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"
#include "erodem/simulation.hpp"

namespace erodem::io {

/// The DEM (file or synthetic) and every raster parameter of `p` on its grid. `by_rows`: on a
/// rank of an MPI run of more than one rank, only its band's rows (and 4 beside them) where
/// the inputs allow it (Terrain::banded; docs/mpi.md, "Reading only the band"), for a
/// Simulation whose backend holds that band (make_simulation); else the whole grid.
Terrain load_terrain(const Params& p, bool by_rows = false);

/// A simulation of `p` on backend `backend` ("auto", "cpu", ...), each MPI rank's on the rows
/// of its band (load_terrain by rows).
Simulation make_simulation(const Params& p, const std::string& backend);

}  // namespace erodem::io
