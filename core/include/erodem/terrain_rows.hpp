// erodem — what a process does with the rows of a Terrain it holds: which rows it owns (all of
// them, or an MPI rank's band when it read only its band's rows: Terrain::banded,
// docs/mpi.md), and what is asked of the whole grid answered from those rows alone: whether a
// cell, a row or the grid has an active cell, and the first bad cell.
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

/// The mask of the rows [row0, row0 + valid.size() / nx) of a terrain (Terrain::mask): `valid`,
/// or none where every cell of them is valid.
inline std::vector<std::uint8_t> rows_mask(std::vector<std::uint8_t> valid) {
  for (const std::uint8_t v : valid)
    if (v == 0) return valid;
  return {};
}

/// Whether any cell of the grid is active, each rank looking at the rows it owns. Collective
/// where the terrain is banded.
inline bool any_active(const Terrain& t) {
  const parallel::Band rows = own_rows(t);
  const auto nx = static_cast<std::size_t>(t.grid.nx);
  bool any = false;
  for (std::size_t i = static_cast<std::size_t>(rows.row0) * nx;
       i < static_cast<std::size_t>(rows.row1) * nx && !any; ++i)
    any = t.active(i);
  return t.banded ? parallel::any(any) : any;
}

/// For each row of the grid, whether it has an active cell (1) or none (0), each rank
/// answering for the rows it owns. Collective where the terrain is banded.
inline std::vector<std::uint8_t> rows_with_active(const Terrain& t) {
  const parallel::Band rows = own_rows(t);
  std::vector<std::uint8_t> any(static_cast<std::size_t>(t.grid.ny), 0);
  for (int r = rows.row0; r < rows.row1; ++r)
    for (int c = 0; c < t.grid.nx && !any[static_cast<std::size_t>(r)]; ++c)
      any[static_cast<std::size_t>(r)] = t.active(static_cast<std::size_t>(r) * t.grid.nx + c);
  return t.banded ? parallel::any_each(std::move(any)) : any;
}

/// For each of `cells` (global, row-major, inside the grid), whether it is active (1) or not
/// (0), each rank answering for the rows it owns: the whole grid's answer on every rank of a
/// banded terrain, whose mask holds its own rows alone. Collective where the terrain is banded.
inline std::vector<std::uint8_t> cells_active(const Terrain& t,
                                              const std::vector<std::int64_t>& cells) {
  const parallel::Band rows = own_rows(t);
  const auto nx = static_cast<std::int64_t>(t.grid.nx);
  std::vector<std::uint8_t> on(cells.size(), 0);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const std::int64_t row = cells[k] / nx;
    if (row >= rows.row0 && row < rows.row1) on[k] = t.active(static_cast<std::size_t>(cells[k]));
  }
  return t.banded ? parallel::any_each(std::move(on)) : on;
}

/// Whether each cell of the grid is active (1) or not (0), row-major: the whole grid's bytes on
/// every rank, each rank giving its own rows'. Collective where the terrain is banded (for
/// Python's Simulation.active and its erosion volumes, which return whole fields; a run never
/// holds it).
inline std::vector<std::uint8_t> active_grid(const Terrain& t) {
  const parallel::Band rows = own_rows(t);
  const auto nx = static_cast<std::size_t>(t.grid.nx);
  const std::size_t first = static_cast<std::size_t>(rows.row0) * nx;
  std::vector<std::uint8_t> own(static_cast<std::size_t>(rows.row1 - rows.row0) * nx);
  for (std::size_t k = 0; k < own.size(); ++k) own[k] = t.active(first + k) ? 1 : 0;
  return t.banded ? parallel::allgather(own) : own;
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
