// erodem — which backend `auto` runs on, and building a backend by name. One rule, used by
// make_backend() and reported by `erodem devices`.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/parallel.hpp"

namespace erodem {

namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool is_pocl(const ClDeviceInfo& d) {
  return d.platform.find("Portable Computing Language") != std::string::npos ||
         d.vendor.find("pocl") != std::string::npos;
}

}  // namespace

bool opencl_selector_matches(const ClDeviceInfo& d, const std::string& selector) {
  const auto colon = selector.find(':');
  const std::string plat = colon == std::string::npos ? "" : lower(selector.substr(0, colon));
  const std::string dev = lower(colon == std::string::npos ? selector : selector.substr(colon + 1));
  const bool plat_ok = plat.empty() || lower(d.platform).find(plat) != std::string::npos ||
                       lower(d.vendor).find(plat) != std::string::npos;
  const bool dev_ok = dev.empty() || lower(d.device).find(dev) != std::string::npos;
  return plat_ok && dev_ok;
}

BackendChoice auto_backend_choice(const std::vector<ClDeviceInfo>& devices,
                                  const std::string& selector) {
  BackendChoice c;
  if (devices.empty()) {
    c.backend = "cpu";
    c.reason = "no OpenCL device (or the OpenCL backend is not built): the CPU reference";
    return c;
  }
  if (!selector.empty()) {
    for (std::size_t k = 0; k < devices.size(); ++k)
      if (opencl_selector_matches(devices[k], selector)) {
        c.backend = "opencl";
        c.device = static_cast<int>(k);
        c.reason = "ERODEM_OPENCL_DEVICE='" + selector + "' selects it";
        return c;
      }
    c.reason = "ERODEM_OPENCL_DEVICE='" + selector +
               "' matches no device: auto (and --backend opencl) fail with exit 2";
    return c;
  }
  const auto gpu =
      std::find_if(devices.begin(), devices.end(), [](const ClDeviceInfo& d) { return d.gpu(); });
  if (gpu != devices.end()) {
    c.backend = "opencl";
    c.device = static_cast<int>(gpu - devices.begin());
    c.reason = parallel::local_size() > 1 ? "an OpenCL GPU (the processes mpirun started on a "
                                            "machine take its GPUs in turn)"
                                          : "the first OpenCL GPU";
    return c;
  }
  c.backend = "cpu";
  c.reason = std::any_of(devices.begin(), devices.end(), is_pocl)
                 ? "no OpenCL GPU: the CPU reference, as fast as OpenCL on the CPU (PoCL) or "
                   "faster at every grid size measured (ERODEM_OPENCL_DEVICE or --backend "
                   "opencl run PoCL)"
                 : "no OpenCL GPU: the CPU reference";
  return c;
}

std::unique_ptr<Backend> make_backend(const std::string& name, const Terrain& terrain,
                                      const Params& params) {
  std::unique_ptr<Backend> b;
  std::string reason = "--backend " + name;
  if (name == "cpu") {
    b = make_cpu_backend(terrain, params);
  } else if (name == "opencl") {
    b = make_opencl_backend(terrain, params);
  } else if (name == "auto") {
    if (params.numerics.precision != Precision::float32) {
      // The OpenCL backend runs float32 only.
      b = make_cpu_backend(terrain, params);
      reason = "auto: float64 runs on the CPU reference (OpenCL runs float32 only)";
    } else {
      const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
      BackendChoice choice = auto_backend_choice(list_opencl_devices(), env ? env : "");
      // MPI (docs/mpi.md): the ranks must run one backend (their collectives come at different
      // points of a step on the two, and the bits would differ), so OpenCL only where every
      // rank would choose it, and every rank says so. Collective: every rank asks (in one
      // process the identity).
      const bool some_cpu = parallel::any(choice.backend == "cpu"),
                 some_opencl = parallel::any(choice.backend != "cpu");
      if (some_cpu && some_opencl) {
        choice.backend = "cpu";
        choice.reason = fmt::format(
            "the CPU reference: not every one of the {} MPI ranks has an OpenCL GPU (here: {})",
            parallel::size(), choice.reason);
      }
      // No choice (a selector that matches nothing): the OpenCL backend says why, exit 2.
      b = choice.backend != "cpu" ? make_opencl_backend(terrain, params)
                                  : make_cpu_backend(terrain, params);
      reason = "auto: " + choice.reason;
    }
  } else {
    throw Error(ExitCode::usage, "backend '" + name + "': expected auto, cpu or opencl" +
                                     (opencl_available() ? "" : " (no OpenCL device here)"));
  }
  b->set_choice_reason(reason);
  return b;
}

}  // namespace erodem
