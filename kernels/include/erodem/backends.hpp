// erodem — building compute backends.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The CPU reference backend in the precision of params.numerics.precision, holding the
/// state built from `terrain` (bed, initial water, rasters, mask) and `params`.
std::unique_ptr<Backend> make_cpu_backend(const Terrain& terrain, const Params& params);

/// A backend by name: "cpu", "opencl", or "auto" (the best available: an OpenCL GPU, else
/// OpenCL on PoCL, else the CPU reference; the CPU reference for float64). Throws
/// erodem::Error(usage) on an unknown name.
std::unique_ptr<Backend> make_backend(const std::string& name, const Terrain& terrain,
                                      const Params& params);

/// The instruction-set level the CPU reference runs at here (ERODEM_CPU_ISA, else the best
/// this CPU supports), e.g. "x86-64-v4 (AVX-512)", and the levels built into this binary
/// ("v2, v3, v4"). A bad ERODEM_CPU_ISA gives its error message as the level.
struct CpuIsaInfo {
  std::string level;
  std::string built;
};
CpuIsaInfo cpu_isa_info();

/// An OpenCL device as list_opencl_devices() reports it.
struct ClDeviceInfo {
  std::string platform;             ///< platform name, e.g. "Portable Computing Language"
  std::string vendor;               ///< platform vendor, e.g. "The pocl project"
  std::string device;               ///< device name
  std::string type;                 ///< "GPU", "CPU", "accelerator" or "other"
  std::uint64_t global_memory = 0;  ///< bytes
  unsigned compute_units = 0;
  bool fp64 = false;               ///< cl_khr_fp64: the ledger reductions run in double
  std::size_t max_work_group = 0;  ///< CL_DEVICE_MAX_WORK_GROUP_SIZE; 0: unknown
  std::string version;             ///< CL_DEVICE_VERSION
  std::string driver;              ///< CL_DRIVER_VERSION
  bool gpu() const { return type == "GPU"; }
  /// "<platform> / <device>": how Backend::device() names an OpenCL backend's device
  std::string label() const { return platform + " / " + device; }
};

/// Every OpenCL device of every platform; empty when there is none or the backend is not
/// built (ERODEM_OPENCL=OFF).
std::vector<ClDeviceInfo> list_opencl_devices();

/// The copy bandwidth of the OpenCL device a backend would run on (ERODEM_OPENCL_DEVICE, else
/// the first GPU, else the first device), counted as STREAM's copy counts it: `bytes` read and
/// `bytes` written by clEnqueueCopyBuffer between two buffers on the device, each copy timed
/// by its profiling event; the median of `repetitions` copies after one untimed. `erodem
/// bench` sets a GPU's kernels against this figure, since the host's says nothing of a GPU's
/// memory. Throws Error (usage) without an OpenCL device.
struct ClCopyBandwidth {
  ClDeviceInfo device;
  std::size_t bytes = 0;  ///< per buffer (the request, capped at a quarter of the device's)
  int repetitions = 0;
  double gbs = 0.0;      ///< median, 1e9 bytes/s, read + written
  double gbs_low = 0.0;  ///< the slowest and fastest copy (GB/s)
  double gbs_high = 0.0;
};
ClCopyBandwidth opencl_copy_bandwidth(std::size_t bytes, int repetitions = 9);

/// Whether the OpenCL backend is built and at least one device is present.
bool opencl_available();

/// Whether ERODEM_OPENCL_DEVICE-style `selector` ("<platform>:<device>", case-insensitive
/// substrings, the platform part matching the platform's name or vendor, either part may be
/// empty; without ':' it names the device) selects `d`.
bool opencl_selector_matches(const ClDeviceInfo& d, const std::string& selector);

/// What `--backend auto` runs a float32 run on (float64 runs always get the CPU reference).
struct BackendChoice {
  std::string backend;  ///< "opencl", "cpu", or "" when auto fails (a selector matching nothing)
  int device = -1;      ///< index into the device list when backend is "opencl"
  std::string reason;   ///< why, in words
};
/// The rule of make_backend("auto"): the device `selector` (ERODEM_OPENCL_DEVICE) names, else
/// the first OpenCL GPU, else the CPU reference. OpenCL on the CPU (PoCL) is not chosen: the
/// CPU reference ran the full step as fast or faster at every grid size measured, 64^2 to
/// 2048^2 cells (docs/performance.md, "auto and PoCL"; a 200 x 5 channel ran 28 times slower
/// on PoCL); ERODEM_OPENCL_DEVICE or --backend opencl still select it.
BackendChoice auto_backend_choice(const std::vector<ClDeviceInfo>& devices,
                                  const std::string& selector);

/// The OpenCL backend (float32), on the device chosen by ERODEM_OPENCL_DEVICE
/// ("<platform substring>:<device substring>", case-insensitive, either part may be empty),
/// else the first GPU, else the first device. Throws Error(usage) when there is no OpenCL
/// device or the backend is not built, Error(config) for params.numerics.precision float64,
/// Error(internal) with the build log when the kernels fail to build.
std::unique_ptr<Backend> make_opencl_backend(const Terrain& terrain, const Params& params);

/// Releases the OpenCL runtimes the backend keeps between backends: one context and built
/// program per device and launch kind, so that a second backend on the device does not build
/// the kernels again. A runtime that a live backend still uses is released with the last such
/// backend; a backend made afterwards builds its runtime afresh. Returns the number of
/// runtimes still held by live backends (0 once every backend is gone; 0 without OpenCL).
///
/// The runtimes are never released during static destruction: an OpenCL implementation may
/// have begun its own teardown by then (Oclgrind aborted with "corrupted double-linked list"
/// when the cache was a static object). A program calls this before it exits, through an
/// OpenClRuntimes object in `main` (the CLI) or at interpreter exit (the Python module
/// registers it with `atexit`); without the call the runtimes are left to the operating
/// system at exit.
std::size_t release_opencl_runtimes();

/// Calls release_opencl_runtimes() when it goes out of scope: declared first in `main`, it
/// releases every OpenCL object before `main` returns.
class OpenClRuntimes {
 public:
  OpenClRuntimes() = default;
  OpenClRuntimes(const OpenClRuntimes&) = delete;
  OpenClRuntimes& operator=(const OpenClRuntimes&) = delete;
  ~OpenClRuntimes() { release_opencl_runtimes(); }
};

}  // namespace erodem
