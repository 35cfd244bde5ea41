// erodem — the statistics merge both backends share: the per-row results of the reductions
// over the active cells (the CPU's row scan, OpenCL's stats_rows) combined in row order into
// FieldStats, so the two backends and any split of the rows add and rank them alike.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "erodem/backend.hpp"

namespace erodem {

/// The statistics of one padded row of DEM cells.
struct RowStats {
  double water = 0, material = 0, sediment = 0;  ///< volumes (m^3)
  double max_depth = -1;   ///< the row's largest depth (m); -1: no active cell
  double max_speed2 = -1;  ///< the row's largest squared speed (m^2/s^2); -1: none
  double speed = -1;       ///< the speed (m/s, hypot) of the cell of max_speed2
  std::int64_t max_depth_cell = -1, max_speed_cell = -1;  ///< row-major DEM cells; -1: none
  std::int64_t bad_cell = -1;  ///< the row's first cell whose state is not physical; -1: none
};

/// The rows merged in order: volumes added; the max depth starts at 0 and a later row takes it
/// when larger (or when none has been taken); the max speed ranks the rows by the squared
/// speed (strictly larger wins: the earlier row keeps a tie); the first bad cell.
inline FieldStats merge_row_stats(const std::vector<RowStats>& rows) {
  FieldStats st;
  st.max_depth = 0.0;
  st.max_speed = 0.0;
  double best_v2 = -1;
  for (const RowStats& row : rows) {
    st.water_volume += row.water;
    st.material_volume += row.material;
    st.sediment_volume += row.sediment;
    if (row.max_depth > st.max_depth || (st.max_depth_cell < 0 && row.max_depth_cell >= 0)) {
      st.max_depth = std::max(0.0, row.max_depth);
      st.max_depth_cell = row.max_depth_cell;
    }
    if (row.max_speed_cell >= 0 && (st.max_speed_cell < 0 || row.max_speed2 > best_v2)) {
      best_v2 = row.max_speed2;
      st.max_speed_cell = row.max_speed_cell;
      st.max_speed = std::max(0.0, row.speed);
    }
    if (st.bad_cell < 0 && row.bad_cell >= 0) st.bad_cell = row.bad_cell;
  }
  return st;
}

}  // namespace erodem
