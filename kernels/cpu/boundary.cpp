// CPU loop of the boundary process: kernels/common/boundary.h on the halo cells.
#include "common/boundary.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_boundary() {
  const cell_params::BoundaryParams<Real> sea = cell_.boundary;
  // the first and last padded rows where they are the grid's ghost rows (their corners keep
  // theirs); in a band of an MPI run they may be halo rows instead, whose ghost columns it
  // fills as on the other rows, as the neighbouring band does (process_table.cpp
  // exact_in_band: no exchange after it)
  const bool north = band_.holds_north_ghost(), south = band_.holds_south_ghost(ny_);
  for (int x = 1; x < W_ - 1; ++x) {
    if (north)
      cell::boundary_fill_cell(x, 0, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                               sediment_.data(), sea);
    if (south)
      cell::boundary_fill_cell(x, H_ - 1, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                               sediment_.data(), sea);
  }
  for (int y = north ? 1 : 0; y < (south ? H_ - 1 : H_); ++y) {
    cell::boundary_fill_cell(0, y, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                             sediment_.data(), sea);
    cell::boundary_fill_cell(W_ - 1, y, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                             sediment_.data(), sea);
  }
}

template void CpuBackend<float>::run_boundary();
template void CpuBackend<double>::run_boundary();

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
