// erodem — what a process does with the rows of a Terrain it holds: which rows it owns (all of
// them, or an MPI rank's band when it read only its band's rows: Terrain::banded,
// docs/mpi.md), and the first bad cell of the grid found from those rows alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/parallel.hpp"

namespace erodem {

/// The DEM rows this process checks and adds up: every row, or on a rank holding its band's
/// rows (Terrain::banded) the rows it owns (the ranks cover every row once between them).
inline parallel::Band own_rows(const Terrain& t) {
  return t.banded ? parallel::Band{t.own0, t.own1} : parallel::Band{0, t.grid.ny};
}

/// The whole grid's mask (nx cells a row) from every rank's `own` rows of `mask`, which holds
/// the rows from `mask_row0` on (ranks in rank order, which is row order), or none where every
/// cell is valid (Terrain::mask). Collective.
inline std::vector<std::uint8_t> gathered_mask(const std::vector<std::uint8_t>& mask, int mask_row0,
                                               parallel::Band own, int nx) {
  const auto at = [&](int row) {
    return mask.begin() + static_cast<std::ptrdiff_t>(row - mask_row0) * nx;
  };
  std::vector<std::uint8_t> all =
      parallel::allgather(std::vector<std::uint8_t>(at(own.row0), at(own.row1)));
  for (const std::uint8_t v : all)
    if (v == 0) return all;
  return {};
}

/// A cell of the grid (global index, row-major; -1: none) and its value.
struct BadCell {
  std::int64_t cell = -1;
  double value = 0.0;
};

/// The first active cell in row-major order whose `value(i)` fails `good(i, value)`, of the
/// rows own_rows gives, agreed by every rank of a banded terrain (each rank's first, in rank
/// order, which is row order): every rank then stops with the message one process gives.
/// Collective where the terrain is banded.
template <class Value, class Good>
BadCell first_bad_cell(const Terrain& t, const Value& value, const Good& good) {
  const parallel::Band rows = own_rows(t);
  const auto nx = static_cast<std::size_t>(t.grid.nx);
  BadCell bad;
  for (std::size_t i = static_cast<std::size_t>(rows.row0) * nx;
       i < static_cast<std::size_t>(rows.row1) * nx && bad.cell < 0; ++i)
    if (t.active(i) && !good(i, value(i))) bad = {static_cast<std::int64_t>(i), value(i)};
  if (!t.banded) return bad;
  for (const BadCell& b : parallel::allgather(std::vector<BadCell>{bad}))
    if (b.cell >= 0) return b;
  return {};
}

}  // namespace erodem
