/* erodem — the common subset of C++ and OpenCL C in which per-cell formulas are written.
 *
 * Every process of MODEL.md is written once, as functions of one cell, in the headers of
 * kernels/common. The CPU reference (kernels/cpu) loops over cells calling them; the OpenCL kernels
 * (kernels/opencl) call the same functions from one work-item per cell. In C++ the
 * functions are templates on the floating-point type `real` (float or double); in OpenCL C
 * `real` is a typedef set by the build options.
 *
 * Storage layout: every field is a padded raster of W = nx + 2 columns by H = ny + 2 rows
 * with a one-cell halo. Cell (x, y) of the padded raster is at index x + y * W; the DEM's
 * cell (col, row) is at x = col + 1, y = row + 1. Halo cells and nodata cells are ghosts
 * whose kind (below) says how water crosses their faces. Row y = 0 is the north halo.
 */
#ifndef ERODEM_KERNELS_COMMON_COMPAT_H
#define ERODEM_KERNELS_COMMON_COMPAT_H

#ifdef __OPENCL_C_VERSION__
#define ERODEM_FN static inline
#define ERODEM_INLINE static inline
#define GLOBAL __global
#define ERODEM_BEGIN_NAMESPACE
#define ERODEM_END_NAMESPACE
typedef uchar erodem_kind_t;
#else
#include <cmath>
#include <cstdint>
namespace erodem {
namespace cell {
using std::cbrt;
using std::fabs;
using std::fmax;
using std::fmin;
using std::isfinite;
using std::sqrt;
typedef std::uint8_t erodem_kind_t;
}  // namespace cell
}  // namespace erodem
#define ERODEM_FN       \
  template <class real> \
  inline
#define ERODEM_INLINE inline
#define GLOBAL
#define ERODEM_BEGIN_NAMESPACE \
  namespace erodem {           \
  namespace cell {
#define ERODEM_END_NAMESPACE \
  }                          \
  }
#endif

/* Cell kinds (the `kind` field). */
#define ERODEM_CELL_ACTIVE 0 /* a DEM cell that carries water, sediment and bed */
#define ERODEM_CELL_WALL 1   /* closed: no flux across any of its faces */
#define ERODEM_CELL_OPEN 2   /* free outflow: takes water from active cells, gives none */
#define ERODEM_CELL_FIXED 3  /* fixed water level (sea): exchanges water both ways, unlimited */

/* Face directions, the order of the four flux fields. */
#define ERODEM_LEFT 0   /* west,  x - 1 */
#define ERODEM_RIGHT 1  /* east,  x + 1 */
#define ERODEM_TOP 2    /* north, y - 1 */
#define ERODEM_BOTTOM 3 /* south, y + 1 */

#endif
