// erodem — what the backends share of their interface (backend.hpp).
#include "erodem/backend.hpp"

#include <fmt/format.h>

#include "erodem/error.hpp"

namespace erodem {

void check_cells(const std::vector<std::int64_t>& cells, int nx, int ny, const char* what) {
  const std::int64_t n = static_cast<std::int64_t>(nx) * ny;
  for (const std::int64_t cell : cells)
    if (cell < 0 || cell >= n)
      throw Error(ExitCode::usage,
                  fmt::format("{}: cell {} is not on the grid of {} x {} (0 .. {})", what, cell, nx,
                              ny, n - 1));
}

void check_row_range(FieldId id, int row0, int row1, int nx, int ny) {
  if (row0 < 0 || row1 > ny || row0 > row1)
    throw Error(ExitCode::usage, fmt::format("field '{}': rows [{}, {}) are not rows of a grid "
                                             "of {} x {} (0 .. {})",
                                             field_info(id).name, row0, row1, nx, ny, ny));
}

void check_rows(FieldId id, int row0, int row1, std::size_t count, int nx, int ny) {
  check_row_range(id, row0, row1, nx, ny);
  const std::size_t expected = static_cast<std::size_t>(row1 - row0) * static_cast<std::size_t>(nx);
  if (count != expected)
    throw Error(ExitCode::data,
                fmt::format("field '{}': {} values for rows [{}, {}) of a grid of {} x {} ({} "
                            "expected)",
                            field_info(id).name, count, row0, row1, nx, ny, expected));
}

std::vector<int> padded_faces(const std::vector<Face>& faces, int nx, int ny) {
  std::vector<int> out;
  out.reserve(faces.size());
  for (const Face& f : faces) {
    const bool ok = f.axis == 0   ? f.col >= -1 && f.col < nx && f.row >= 0 && f.row < ny
                    : f.axis == 1 ? f.col >= 0 && f.col < nx && f.row >= -1 && f.row < ny
                                  : false;
    if (!ok)
      throw Error(ExitCode::usage,
                  fmt::format("faces: face (col {}, row {}, axis {}) is not on the grid of {} x {}",
                              f.col, f.row, f.axis, nx, ny));
    const std::int64_t i =
        static_cast<std::int64_t>(f.col + 1) +
        static_cast<std::int64_t>(f.row + 1) * (static_cast<std::int64_t>(nx) + 2);
    out.push_back(static_cast<int>(2 * i + f.axis));
  }
  return out;
}

}  // namespace erodem
