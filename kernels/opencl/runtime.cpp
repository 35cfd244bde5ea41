// erodem — the OpenCL runtime of a device: the device ERODEM_OPENCL_DEVICE selects (else the
// first GPU, else the first device), its context, the launch kind (whole rows on CPU devices)
// and the build options, with the program built once per device and launch kind and kept until
// release_opencl_runtimes() (backends.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/parallel.hpp"
#include "opencl/devices.hpp"
#include "opencl/launch.hpp"
#include "opencl/opencl_backend.hpp"

namespace erodem::opencl {

RowLaunch whole_row_launch(std::size_t W, std::size_t limit) {
  const std::size_t hi = std::min<std::size_t>({W, limit, 1024});  // ERODEM_CELL_GROUP_MAX
  const std::size_t lo = std::min<std::size_t>(32, hi);
  RowLaunch best{hi, W % hi};
  for (std::size_t g = hi; g >= lo && g > 0; --g)
    if (W % g < best.tail) best = {g, W % g};
  return best;
}

namespace {

using RuntimeMap = std::map<std::pair<cl_device_id, bool>, std::shared_ptr<Runtime> >;

/// The runtimes built so far, by device and launch kind (whole rows or not).
struct RuntimeCache {
  std::mutex mutex;
  RuntimeMap runtimes;
};

/// The process's cache, created on first use and never destroyed: its runtimes are released
/// by release_opencl_runtimes() only, never by a static destructor, which would run after the
/// OpenCL implementation may have begun its own teardown (backends.hpp).
RuntimeCache& runtime_cache() {
  static RuntimeCache* const cache = new RuntimeCache;
  return *cache;
}

}  // namespace

const DeviceEntry& choose_device(const std::vector<DeviceEntry>& devices,
                                 const std::string& selector) {
  if (devices.empty())
    throw Error(ExitCode::usage,
                "backend 'opencl': no OpenCL platform or device found (install an OpenCL "
                "driver, e.g. pocl-opencl-icd or the GPU vendor's, or use --backend cpu)");
  if (!selector.empty()) {
    for (const auto& d : devices)
      if (opencl_selector_matches(d.info, selector)) return d;
    throw Error(ExitCode::usage, fmt::format("ERODEM_OPENCL_DEVICE='{}': no OpenCL device matches "
                                             "'<platform>:<device>'; devices: {}",
                                             selector, describe(devices)));
  }
  // the first GPU; each process a launcher started on a machine (the ranks of an MPI run, an
  // ensemble's members) its own, in turn (local_rank)
  std::vector<const DeviceEntry*> gpus;
  for (const auto& d : devices)
    if (d.info.gpu()) gpus.push_back(&d);
  if (!gpus.empty()) return *gpus[static_cast<std::size_t>(parallel::local_rank()) % gpus.size()];
  return devices.front();
}

std::shared_ptr<Runtime> runtime_for(const std::string& selector) {
  RuntimeCache& cache = runtime_cache();
  const auto devices = enumerate_devices();
  const DeviceEntry* chosen = &choose_device(devices, selector);

  // Whole rows on CPU devices (PoCL vectorises across a row's work-items only where no
  // per-work-item condition guards the loads), unless a tuning size is set.
  const char* wg_env = std::getenv("ERODEM_OPENCL_WG");
  const bool whole_rows = chosen->info.type == "CPU" && !(wg_env && *wg_env);
  std::lock_guard<std::mutex> lock(cache.mutex);
  auto& slot = cache.runtimes[{chosen->device, whole_rows}];
  if (slot) return slot;
  auto rt = std::make_shared<Runtime>();
  rt->info = chosen->info;
  rt->platform = chosen->platform;
  rt->device = chosen->device;
  rt->fp64 = chosen->info.fp64;
  rt->whole_rows = whole_rows;
  rt->max_work_group = device_value<std::size_t>(rt->device, CL_DEVICE_MAX_WORK_GROUP_SIZE);
  rt->base_align = std::max<std::size_t>(
      1, device_value<cl_uint>(rt->device, CL_DEVICE_MEM_BASE_ADDR_ALIGN) / 8);
  rt->max_alloc =
      static_cast<std::size_t>(device_value<cl_ulong>(rt->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE));
  const cl_context_properties props[] = {CL_CONTEXT_PLATFORM,
                                         reinterpret_cast<cl_context_properties>(rt->platform), 0};
  cl_int err = CL_SUCCESS;
  cl_device_id device = rt->device;
  rt->context = Context(clCreateContext(props, 1, &device, nullptr, nullptr, &err));
  check(err, "clCreateContext");
  // IEEE float32 as on the CPU: no fast-math options; correctly rounded divide and sqrt
  // where the device offers them; the kernels switch FP_CONTRACT off.
  rt->options = "-cl-std=CL1.2 -D real=float";
  if (rt->fp64) rt->options += " -D ERODEM_HAVE_FP64=1";
  if (rt->whole_rows) rt->options += " -D ERODEM_WHOLE_ROWS=1";
  rt->options += tally_slot_options();
  const auto fp = device_value<cl_device_fp_config>(rt->device, CL_DEVICE_SINGLE_FP_CONFIG);
  if (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT)
    rt->options += " -cl-fp32-correctly-rounded-divide-sqrt";
  build_program(*rt);
  slot = rt;
  return rt;
}

}  // namespace erodem::opencl

namespace erodem {

std::size_t release_opencl_runtimes() {
  opencl::RuntimeMap taken;
  {
    opencl::RuntimeCache& cache = opencl::runtime_cache();
    std::lock_guard<std::mutex> lock(cache.mutex);
    taken.swap(cache.runtimes);
  }
  std::vector<std::weak_ptr<opencl::Runtime> > released;
  for (const auto& entry : taken) released.push_back(entry.second);
  taken.clear();  // the runtimes no backend holds: context and program released here
  return static_cast<std::size_t>(
      std::count_if(released.begin(), released.end(), [](const auto& w) { return !w.expired(); }));
}

}  // namespace erodem
