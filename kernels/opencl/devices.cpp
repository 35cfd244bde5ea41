// erodem — OpenCL device enumeration: every device of every platform with its name, type,
// memory, compute units, fp64 and versions; and the public list_opencl_devices() and
// opencl_available() built on it.
#include "opencl/devices.hpp"

#include <fmt/format.h>

#include "erodem/backends.hpp"

namespace erodem {
namespace opencl {

namespace {

std::string platform_string(cl_platform_id p, cl_platform_info what) {
  std::size_t size = 0;
  if (clGetPlatformInfo(p, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string s(size, '\0');
  if (clGetPlatformInfo(p, what, size, s.data(), nullptr) != CL_SUCCESS) return {};
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::string device_string(cl_device_id d, cl_device_info what) {
  std::size_t size = 0;
  if (clGetDeviceInfo(d, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string s(size, '\0');
  if (clGetDeviceInfo(d, what, size, s.data(), nullptr) != CL_SUCCESS) return {};
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

}  // namespace

std::vector<DeviceEntry> enumerate_devices() {
  std::vector<DeviceEntry> out;
  cl_uint np = 0;
  if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) return out;
  std::vector<cl_platform_id> platforms(np);
  if (clGetPlatformIDs(np, platforms.data(), nullptr) != CL_SUCCESS) return out;
  for (cl_platform_id p : platforms) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS || nd == 0) continue;
    std::vector<cl_device_id> devices(nd);
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, nd, devices.data(), nullptr) != CL_SUCCESS) continue;
    for (cl_device_id d : devices) {
      DeviceEntry e{p, d, {}};
      e.info.platform = platform_string(p, CL_PLATFORM_NAME);
      e.info.vendor = platform_string(p, CL_PLATFORM_VENDOR);
      e.info.device = device_string(d, CL_DEVICE_NAME);
      const auto type = device_value<cl_device_type>(d, CL_DEVICE_TYPE);
      e.info.type = (type & CL_DEVICE_TYPE_GPU)           ? "GPU"
                    : (type & CL_DEVICE_TYPE_CPU)         ? "CPU"
                    : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                          : "other";
      e.info.global_memory = device_value<cl_ulong>(d, CL_DEVICE_GLOBAL_MEM_SIZE);
      e.info.compute_units = device_value<cl_uint>(d, CL_DEVICE_MAX_COMPUTE_UNITS);
      const std::string ext = " " + device_string(d, CL_DEVICE_EXTENSIONS) + " ";
      e.info.fp64 = ext.find(" cl_khr_fp64 ") != std::string::npos;
      std::size_t wg = 0;
      if (clGetDeviceInfo(d, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof wg, &wg, nullptr) == CL_SUCCESS)
        e.info.max_work_group = wg;
      e.info.version = device_string(d, CL_DEVICE_VERSION);
      e.info.driver = device_string(d, CL_DRIVER_VERSION);
      out.push_back(std::move(e));
    }
  }
  return out;
}

std::string describe(const std::vector<DeviceEntry>& devices) {
  std::string s;
  for (const auto& d : devices)
    s += fmt::format("{}'{}:{}' ({})", s.empty() ? "" : ", ", d.info.platform, d.info.device,
                     d.info.type);
  return s.empty() ? "none" : s;
}

}  // namespace opencl

// ---- the public functions -----------------------------------------------------------------

std::vector<ClDeviceInfo> list_opencl_devices() {
  std::vector<ClDeviceInfo> out;
  for (auto& e : opencl::enumerate_devices()) out.push_back(std::move(e.info));
  return out;
}

bool opencl_available() {
  return !opencl::enumerate_devices().empty();
}

}  // namespace erodem
