// CPU loop of the flow process: kernels/common/flow.h over every padded cell (ghosts give
// water too), then the new fluxes become the current ones.
#include "common/flow.h"

#include "cpu/cpu_backend.hpp"

namespace erodem {

template <class Real>
void CpuBackend<Real>::run_flow(Real dt) {
  const auto& f = params_.flow;
  const Real g = static_cast<Real>(f.gravity);
  const Kind* kind = kind_.data();
  const Real *b = bed_.data(), *d = depth_.data();
  const Real *fl = flux_[0].data(), *fr = flux_[1].data(), *ft = flux_[2].data(),
             *fb = flux_[3].data();
  Real *ol = flux_next_[0].data(), *orr = flux_next_[1].data(), *ot = flux_next_[2].data(),
       *ob = flux_next_[3].data();
  if (f.scheme == FlowScheme::pipes) {
    const Real area_pipe = static_cast<Real>(f.pipe_area);
    const Real length = static_cast<Real>(f.pipe_length);
    for_rows(0, H_, [&](int y) {
      for (int x = 0; x < W_; ++x)
        cell::flow_pipes_cell(x, y, W_, H_, kind, b, d, dx_.data(), dy_.data(), area_.data(), fl,
                              fr, ft, fb, ol, orr, ot, ob, dt, g, area_pipe, length);
    });
  } else {
    const Real theta = static_cast<Real>(f.theta);
    const Real dry = static_cast<Real>(params_.numerics.dry_depth);
    for_rows(0, H_, [&](int y) {
      for (int x = 0; x < W_; ++x)
        cell::flow_local_inertial_cell(x, y, W_, H_, kind, b, d, manning_.data(), dx_.data(),
                                       dy_.data(), area_.data(), fl, fr, ft, fb, ol, orr, ot, ob,
                                       dt, g, theta, dry);
    });
  }
  std::swap(flux_, flux_next_);
}

template void CpuBackend<float>::run_flow(float);
template void CpuBackend<double>::run_flow(double);

}  // namespace erodem
