// erodem — the OpenCL backend's public functions in a build without OpenCL (ERODEM_OPENCL off:
// kernels/CMakeLists.txt compiles this file instead of the others of kernels/opencl/): no
// devices, and --backend opencl exits 2 saying how to build it.
#include "erodem/backends.hpp"
#include "erodem/error.hpp"

#ifndef ERODEM_HAVE_OPENCL

namespace erodem {

std::vector<ClDeviceInfo> list_opencl_devices() {
  return {};
}
bool opencl_available() {
  return false;
}
std::size_t release_opencl_runtimes() {
  return 0;
}
ClCopyBandwidth opencl_copy_bandwidth(std::size_t, int) {
  throw Error(ExitCode::usage, "the OpenCL copy bandwidth: this build has no OpenCL backend");
}
std::unique_ptr<Backend> make_opencl_backend(const Terrain&, const Params&) {
  throw Error(ExitCode::usage,
              "backend 'opencl': this build has no OpenCL backend (configure with "
              "-DERODEM_OPENCL=ON and an OpenCL SDK, e.g. ocl-icd-opencl-dev + opencl-headers)");
}

}  // namespace erodem

#endif
