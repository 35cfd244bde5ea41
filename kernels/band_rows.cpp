#include "band_rows.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "erodem/error.hpp"
#include "erodem/parallel.hpp"
#include "erodem/process.hpp"

namespace erodem {

BandRows band_rows(const Params& params, int ny) {
  BandRows b;
  b.rows = ny + 2;
  b.own1 = b.rows - 1;
  const int ranks = parallel::size();
  if (ranks <= 1) return b;
  b.halo = band_halo_rows(params);
  if (process_info(Process::transport).enabled(params) &&
      params.transport.scheme == TransportScheme::semi_lagrangian)
    throw Error(ExitCode::config,
                "transport.scheme = \"semi_lagrangian\": not supported under MPI with more "
                "than one rank (its departure points may lie beyond the halo of " +
                    std::to_string(b.halo) +
                    " rows); use transport.scheme = \"conservative\" or run one process");
  const int r = parallel::rank();
  const parallel::Band band = parallel::band(ny, r, ranks);
  if (band.row1 - band.row0 < b.halo)
    throw Error(ExitCode::usage,
                fmt::format("mpirun -np {}: the grid's {} rows give rank {} {} rows, and each "
                            "rank needs at least {} (the halo); run fewer ranks",
                            ranks, ny, r, band.row1 - band.row0, b.halo));
  const int y0 = r == 0 ? 0 : band.row0 + 1 - b.halo;
  const int y1 = r == ranks - 1 ? ny + 2 : band.row1 + 1 + b.halo;
  b.banded = true;
  b.row0 = y0;
  b.rows = y1 - y0;
  b.own0 = band.row0 + 1 - y0;
  b.own1 = band.row1 + 1 - y0;
  return b;
}

std::vector<int> cell_owners(const std::vector<std::int64_t>& cells, int nx, int ny) {
  std::vector<int> owner;
  owner.reserve(cells.size());
  const int ranks = parallel::size();
  for (const std::int64_t cell : cells)
    owner.push_back(ranks <= 1 ? 0
                               : parallel::owner_of_row(ny, static_cast<int>(cell / nx), ranks));
  return owner;
}

std::vector<int> face_owners(const std::vector<Face>& faces, int ny) {
  std::vector<int> owner(faces.size(), 0);
  const int ranks = parallel::size();
  if (ranks > 1)
    for (std::size_t j = 0; j < faces.size(); ++j)
      owner[j] = parallel::owner_of_row(ny, std::max(faces[j].row, 0), ranks);
  return owner;
}

}  // namespace erodem
