// CPU loop of the boundary process: kernels/common/boundary.h on the halo cells.
#include "common/boundary.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

template <class Real>
void CpuBackend<Real>::run_boundary() {
  const cell_params::BoundaryParams<Real> sea = cell_.boundary;
  for (int x = 1; x < W_ - 1; ++x) {
    cell::boundary_fill_cell(x, 0, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                             sediment_.data(), sea);
    cell::boundary_fill_cell(x, H_ - 1, W_, H_, kind_.data(), bed_.data(), depth_.data(),
                             sediment_.data(), sea);
  }
  for (int y = 1; y < H_ - 1; ++y) {
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
