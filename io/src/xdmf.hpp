// erodem — the XDMF sidecar of a result file (private to io/src; xdmf.cpp), for ParaView.
#pragma once

#include <string>
#include <vector>

#include "erodem/fields.hpp"
#include "erodem/grid.hpp"

namespace erodem::io {

/// Writes the XDMF sidecar of result file `path` (xdmf_path(path), through a temporary file):
/// one uniform rectilinear grid per snapshot time in `times`, on coordinates `xname` and
/// `yname`, referencing the datasets of `infos`.
void write_xdmf(const std::string& path, const Grid& grid, const std::string& xname,
                const std::string& yname, const std::vector<double>& times,
                const std::vector<FieldInfo>& infos);

}  // namespace erodem::io
