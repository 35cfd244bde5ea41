// erodem viewer — level of detail: block decimation of large grids for drawing.
#pragma once

#include <cstddef>
#include <vector>

namespace erodem::viz {

/// A block-decimated view of an `nx` x `ny` grid: coarse cell (i, j) stands for the fine
/// cells [i*factor, min(nx, (i+1)*factor)) x [j*factor, min(ny, (j+1)*factor)). Partial
/// blocks at the east and south edges are kept, so the drawing covers the whole grid.
struct Lod {
  int factor = 1;      ///< fine cells per coarse cell along each axis (1 = full resolution)
  int nx = 0, ny = 0;  ///< fine grid size (cells)
  int coarse_nx = 0, coarse_ny = 0;  ///< coarse grid size (cells)

  /// The smallest factor whose coarse grid has at most `max_cells` cells (`max_cells` >= 1).
  static Lod for_budget(int nx, int ny, std::size_t max_cells);
  /// Fractional fine column of coarse column `i`'s centre (the mean of its fine cells).
  double fine_col(int i) const;
  /// Fractional fine row of coarse row `j`'s centre.
  double fine_row(int j) const;
  std::size_t coarse_cells() const {
    return static_cast<std::size_t>(coarse_nx) * static_cast<std::size_t>(coarse_ny);
  }
};

/// How a block of fine values becomes one coarse value.
enum class Reduce {
  mean,    ///< mean of the block's finite values (NaN when none): continuous fields
  sample,  ///< the value at the block's centre cell: categories (terrain classes)
};

/// `values` (nx * ny, row-major) decimated to lod.coarse_nx * lod.coarse_ny values. With
/// factor 1 the values are returned as they are.
std::vector<float> decimate(const std::vector<float>& values, const Lod& lod, Reduce reduce);

}  // namespace erodem::viz
