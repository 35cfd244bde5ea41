// erodem — the OpenCL sources embedded at build time (kernels/embed_opencl.cmake writes the
// definitions into the build tree): kernels/common/*.h and kernels/opencl/*.cl by file name.
#pragma once

#include <cstddef>

namespace erodem::opencl {

struct EmbeddedSource {
  const char* name;  ///< file name, e.g. "flow.h" or "flow.cl"
  const char* text;  ///< the file's text
};

extern const EmbeddedSource kEmbeddedSources[];
extern const std::size_t kEmbeddedSourceCount;

}  // namespace erodem::opencl
