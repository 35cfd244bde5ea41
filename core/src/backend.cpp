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

}  // namespace erodem
