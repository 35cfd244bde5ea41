// erodem — building compute backends.
#pragma once

#include <memory>
#include <string>

#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The CPU reference backend in the precision of params.numerics.precision, holding the
/// state built from `terrain` (bed, initial water, rasters, mask) and `params`.
std::unique_ptr<Backend> make_cpu_backend(const Terrain& terrain, const Params& params);

/// A backend by name: "cpu", or "auto" (the best available; the CPU reference until the
/// OpenCL backend exists). Throws erodem::Error(usage) on an unknown name.
std::unique_ptr<Backend> make_backend(const std::string& name, const Terrain& terrain,
                                      const Params& params);

}  // namespace erodem
