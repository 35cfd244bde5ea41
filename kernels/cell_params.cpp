// erodem — the one instantiation of the conversion of cell_params.hpp, compiled once for both
// backends and every instruction set.
#include "cell_params.hpp"

namespace erodem {

template CellParams<float> cell_params_of<float>(const Params&);
template CellParams<double> cell_params_of<double>(const Params&);
template ParamBytes cell_params_bytes(const CellParams<float>&, Process);
template ParamBytes cell_params_bytes(const CellParams<double>&, Process);

}  // namespace erodem
