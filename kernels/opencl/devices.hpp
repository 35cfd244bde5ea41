// erodem — OpenCL device enumeration (private to the OpenCL backend): every device of every
// platform with what erodem reports of it (devices.cpp).
#pragma once

#include <string>
#include <vector>

#include "opencl/opencl_backend.hpp"

namespace erodem::opencl {

/// One value of clGetDeviceInfo (check()ed).
template <class T>
T device_value(cl_device_id d, cl_device_info what) {
  T v{};
  check(clGetDeviceInfo(d, what, sizeof(T), &v, nullptr), "clGetDeviceInfo");
  return v;
}

/// One device of one platform, with what list_opencl_devices() reports of it.
struct DeviceEntry {
  cl_platform_id platform;
  cl_device_id device;
  ClDeviceInfo info;
};

/// Every device of every platform, in platform then device order; empty when none.
std::vector<DeviceEntry> enumerate_devices();

/// The devices as "'<platform>:<device>' (<type>), ...", or "none", for messages.
std::string describe(const std::vector<DeviceEntry>& devices);

/// The device a backend runs on: the first that `selector` (ERODEM_OPENCL_DEVICE) matches, or
/// without a selector the first GPU, else the first device. Throws Error (usage) when there is
/// no device or the selector matches none.
const DeviceEntry& choose_device(const std::vector<DeviceEntry>& devices,
                                 const std::string& selector);

}  // namespace erodem::opencl
