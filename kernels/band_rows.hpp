// erodem — the rows of the padded raster a backend holds in a band of an MPI run
// (docs/mpi.md), shared by the CPU reference and the OpenCL backend: which rows it holds,
// which it owns, how deep its halo is, and which rank owns a DEM cell or a section face.
#pragma once

#include <cstdint>
#include <vector>

#include "erodem/backend.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The padded rows a backend holds: all of them in one process; in a band of an MPI run of
/// N > 1 ranks its own DEM rows, `halo` rows of each neighbouring band and the grid's ghost
/// row where the band meets the north or south edge. Rows below are the raster's (0 is the
/// first row it holds), so DEM row r is raster row r + 1 - row0.
struct BandRows {
  bool banded = false;  ///< a band of an MPI run of more than one rank
  /// Rows of halo on either side of the own rows: 2, as the local-inertial and shallow-water
  /// faces read the cells (and faces) beyond the face's two cells; 1 with pipes, whose
  /// sweeps read the four neighbours only (tests/mpi.sh: a halo of 1 row changes the
  /// local-inertial and shallow-water results, and not the pipes').
  int halo = 1;
  int row0 = 0;  ///< the global padded row of the raster's row 0
  int rows = 0;  ///< the padded rows held (the raster's height H)
  /// The rows owned: computed, tallied and written here (the others are halo rows, received
  /// after every sweep, or the grid's ghost rows). One process: 1 and H - 1.
  int own0 = 1, own1 = 0;

  /// Whether the raster holds DEM cell `cell` of a grid nx wide (its own or halo rows), and
  /// whether this rank owns it.
  bool holds(std::int64_t cell, int nx) const {
    const std::int64_t y = cell / nx + 1 - row0;
    return y >= 0 && y < rows;
  }
  bool owns(std::int64_t cell, int nx) const {
    const std::int64_t y = cell / nx + 1 - row0;
    return y >= own0 && y < own1;
  }
  /// The raster index (padded rows W = nx + 2 wide) of DEM cell `cell`, which it holds.
  std::int64_t padded(std::int64_t cell, int nx) const {
    return (cell % nx + 1) + (cell / nx + 1 - row0) * static_cast<std::int64_t>(nx + 2);
  }
  /// Whether the raster's first (last) row is the grid's north (south) ghost row, not a halo
  /// row that the neighbouring band gives; `ny` DEM rows.
  bool holds_north_ghost() const { return row0 == 0; }
  bool holds_south_ghost(int ny) const { return row0 + rows == ny + 2; }
  /// A face's code (padded_faces: twice its cell's global padded index, plus its direction)
  /// in the raster, for a face this rank owns (face_owners).
  int face_code(int code, int nx) const { return code - 2 * row0 * (nx + 2); }
};

/// The rows this process holds of a grid of `ny` DEM rows: the whole padded raster without
/// MPI (or with one rank), else rank parallel::rank()'s band. Throws Error(config) for a
/// semi-Lagrangian transport under N > 1 ranks (its departure points may lie beyond the
/// halo) and Error(usage) for bands thinner than the halo.
BandRows band_rows(const Params& params, int ny);

/// The rank owning each of `cells` (DEM cells of a grid nx x ny, row-major), for
/// parallel::gather_owned: the rank of its row's band; all 0 in one process.
std::vector<int> cell_owners(const std::vector<std::int64_t>& cells, int nx, int ny);

/// The rank owning each face of sections and outlets (set_faces): the band of the cell west
/// or north of it (the north ghost row's faces the first band's), whose raster then holds its
/// far cell too; all 0 in one process.
std::vector<int> face_owners(const std::vector<Face>& faces, int ny);

}  // namespace erodem
