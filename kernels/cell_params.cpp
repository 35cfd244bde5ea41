// erodem — the conversion of cell_params.hpp, compiled once for both backends and every
// instruction set, with the expressions each backend used to write on its own.
#include "cell_params.hpp"

#include <cmath>
#include <limits>

namespace erodem {

template <class real>
CellParams<real> cell_params_of(const Params& params) {
  const auto r = [](double v) { return static_cast<real>(v); };
  CellParams<real> c{};
  c.boundary.sea_level = r(params.boundary.sea_level);

  const auto& f = params.flow;
  c.flow.gravity = r(f.gravity);
  c.flow.theta = r(f.theta);
  c.flow.dry_depth = r(params.numerics.dry_depth);
  c.flow.pipe_area = r(f.pipe_area);
  c.flow.pipe_length = r(f.pipe_length);

  c.water.velocity_min_depth = r(params.numerics.velocity_min_depth);

  const auto& e = params.erosion;
  c.erosion.capacity_k = r(e.sediment_capacity);
  c.erosion.dissolving_rate = r(e.dissolving_rate);
  c.erosion.deposition_rate = r(e.deposition_rate);
  c.erosion.min_tilt = r(e.min_tilt);
  c.erosion.min_depth = r(e.min_depth);
  c.erosion.bedrock =
      e.bedrock_level ? r(*e.bedrock_level) : -std::numeric_limits<real>::infinity();

  const double pi = 3.14159265358979323846;
  c.thermal.rate = r(params.thermal.rate);
  c.thermal.tan_talus = r(std::tan(params.thermal.talus_angle * pi / 180.0));

  c.evaporation.rate = r(params.evaporation.rate);
  c.evaporation.wetness_time = r(params.numerics.wetness_time);
  c.evaporation.evaporate = c.evaporation.rate > real(0) ? 1 : 0;
  return c;
}

template <class real>
ParamBytes cell_params_bytes(const CellParams<real>& c, Process p) {
  const auto of = [](const auto& v) { return ParamBytes{&v, sizeof v}; };
  switch (p) {
    case Process::boundary:
      return of(c.boundary);
    case Process::flow:
      return of(c.flow);
    case Process::water:
      return of(c.water);
    case Process::erosion:
      return of(c.erosion);
    case Process::thermal:
      return of(c.thermal);
    case Process::evaporation:
      return of(c.evaporation);
    default:
      return {};
  }
}

template CellParams<float> cell_params_of<float>(const Params&);
template CellParams<double> cell_params_of<double>(const Params&);
template ParamBytes cell_params_bytes(const CellParams<float>&, Process);
template ParamBytes cell_params_bytes(const CellParams<double>&, Process);

}  // namespace erodem
