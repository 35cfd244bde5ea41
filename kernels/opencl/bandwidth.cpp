// erodem — the copy bandwidth of an OpenCL device's memory (opencl_copy_bandwidth,
// backends.hpp), for `erodem bench`: clEnqueueCopyBuffer between two device buffers, each
// copy timed by its profiling event (device time, no launch latency).

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "erodem/backends.hpp"
#include "opencl/devices.hpp"
#include "opencl/opencl_backend.hpp"

namespace erodem {

ClCopyBandwidth opencl_copy_bandwidth(std::size_t bytes, int repetitions) {
  using namespace opencl;
  const auto devices = enumerate_devices();
  const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
  const DeviceEntry& d = choose_device(devices, env ? env : "");
  ClCopyBandwidth out;
  out.device = d.info;
  out.repetitions = std::max(1, repetitions);
  const auto max_alloc =
      static_cast<std::size_t>(device_value<cl_ulong>(d.device, CL_DEVICE_MAX_MEM_ALLOC_SIZE));
  const auto global = static_cast<std::size_t>(d.info.global_memory);
  // Two buffers: each at most the largest allocation and a quarter of the device's memory.
  out.bytes = std::max<std::size_t>(4096, std::min({bytes, max_alloc, global / 4}) / 4096 * 4096);

  cl_int err = CL_SUCCESS;
  cl_device_id device = d.device;
  const cl_context_properties props[] = {CL_CONTEXT_PLATFORM,
                                         reinterpret_cast<cl_context_properties>(d.platform), 0};
  Context context(clCreateContext(props, 1, &device, nullptr, nullptr, &err));
  check(err, "clCreateContext");
  Queue queue(clCreateCommandQueue(context.get(), device, CL_QUEUE_PROFILING_ENABLE, &err));
  check(err, "clCreateCommandQueue");
  Buffer a(clCreateBuffer(context.get(), CL_MEM_READ_WRITE, out.bytes, nullptr, &err));
  check(err, "clCreateBuffer");
  Buffer b(clCreateBuffer(context.get(), CL_MEM_READ_WRITE, out.bytes, nullptr, &err));
  check(err, "clCreateBuffer");
  const cl_uchar zero = 0;  // first touch: both buffers resident on the device
  check(clEnqueueFillBuffer(queue.get(), a.get(), &zero, 1, 0, out.bytes, 0, nullptr, nullptr),
        "clEnqueueFillBuffer");
  check(clEnqueueFillBuffer(queue.get(), b.get(), &zero, 1, 0, out.bytes, 0, nullptr, nullptr),
        "clEnqueueFillBuffer");
  std::vector<double> gbs;
  for (int k = 0; k <= out.repetitions; ++k) {
    cl_event ev = nullptr;
    cl_mem src = k % 2 ? b.get() : a.get(), dst = k % 2 ? a.get() : b.get();
    check(clEnqueueCopyBuffer(queue.get(), src, dst, 0, 0, out.bytes, 0, nullptr, &ev),
          "clEnqueueCopyBuffer");
    check(clWaitForEvents(1, &ev), "clWaitForEvents");
    const double seconds = take_event_seconds(ev);
    if (k > 0 && seconds > 0) gbs.push_back(2e-9 * out.bytes / seconds);
  }
  if (gbs.empty()) return out;
  std::sort(gbs.begin(), gbs.end());
  const std::size_t n = gbs.size();
  out.gbs = n % 2 ? gbs[n / 2] : 0.5 * (gbs[n / 2 - 1] + gbs[n / 2]);
  out.gbs_low = gbs.front();
  out.gbs_high = gbs.back();
  return out;
}

}  // namespace erodem
