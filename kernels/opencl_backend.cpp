// erodem — the OpenCL backend: the kernels of kernels/opencl/*.cl (each calling the per-cell
// functions of kernels/common/*.h) run over the padded raster, with the same buffers, swaps
// and process order as the CPU reference (kernels/cpu). Built when ERODEM_HAVE_OPENCL is
// defined; otherwise only the functions that say the backend is not built.
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/initial_state.hpp"

#ifndef ERODEM_HAVE_OPENCL

namespace erodem {

std::vector<ClDeviceInfo> list_opencl_devices() {
  return {};
}
bool opencl_available() {
  return false;
}
std::unique_ptr<Backend> make_opencl_backend(const Terrain&, const Params&) {
  throw Error(ExitCode::usage,
              "backend 'opencl': this build has no OpenCL backend (configure with "
              "-DERODEM_OPENCL=ON and an OpenCL SDK, e.g. ocl-icd-opencl-dev + opencl-headers)");
}

}  // namespace erodem

#else

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>

#include "common/compat.h"
#include "opencl/embedded_sources.hpp"
#include "opencl/opencl_backend.hpp"
#include "stagger.hpp"

namespace erodem {
namespace opencl {

// ---- errors ---------------------------------------------------------------------------

const char* error_name(cl_int code) {
  switch (code) {
#define ERODEM_CL_CASE(c) \
  case c:                 \
    return #c;
    ERODEM_CL_CASE(CL_SUCCESS)
    ERODEM_CL_CASE(CL_DEVICE_NOT_FOUND)
    ERODEM_CL_CASE(CL_DEVICE_NOT_AVAILABLE)
    ERODEM_CL_CASE(CL_COMPILER_NOT_AVAILABLE)
    ERODEM_CL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    ERODEM_CL_CASE(CL_OUT_OF_RESOURCES)
    ERODEM_CL_CASE(CL_OUT_OF_HOST_MEMORY)
    ERODEM_CL_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    ERODEM_CL_CASE(CL_MEM_COPY_OVERLAP)
    ERODEM_CL_CASE(CL_IMAGE_FORMAT_MISMATCH)
    ERODEM_CL_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    ERODEM_CL_CASE(CL_BUILD_PROGRAM_FAILURE)
    ERODEM_CL_CASE(CL_MAP_FAILURE)
    ERODEM_CL_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    ERODEM_CL_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    ERODEM_CL_CASE(CL_COMPILE_PROGRAM_FAILURE)
    ERODEM_CL_CASE(CL_LINKER_NOT_AVAILABLE)
    ERODEM_CL_CASE(CL_LINK_PROGRAM_FAILURE)
    ERODEM_CL_CASE(CL_DEVICE_PARTITION_FAILED)
    ERODEM_CL_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    ERODEM_CL_CASE(CL_INVALID_VALUE)
    ERODEM_CL_CASE(CL_INVALID_DEVICE_TYPE)
    ERODEM_CL_CASE(CL_INVALID_PLATFORM)
    ERODEM_CL_CASE(CL_INVALID_DEVICE)
    ERODEM_CL_CASE(CL_INVALID_CONTEXT)
    ERODEM_CL_CASE(CL_INVALID_QUEUE_PROPERTIES)
    ERODEM_CL_CASE(CL_INVALID_COMMAND_QUEUE)
    ERODEM_CL_CASE(CL_INVALID_HOST_PTR)
    ERODEM_CL_CASE(CL_INVALID_MEM_OBJECT)
    ERODEM_CL_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    ERODEM_CL_CASE(CL_INVALID_IMAGE_SIZE)
    ERODEM_CL_CASE(CL_INVALID_SAMPLER)
    ERODEM_CL_CASE(CL_INVALID_BINARY)
    ERODEM_CL_CASE(CL_INVALID_BUILD_OPTIONS)
    ERODEM_CL_CASE(CL_INVALID_PROGRAM)
    ERODEM_CL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    ERODEM_CL_CASE(CL_INVALID_KERNEL_NAME)
    ERODEM_CL_CASE(CL_INVALID_KERNEL_DEFINITION)
    ERODEM_CL_CASE(CL_INVALID_KERNEL)
    ERODEM_CL_CASE(CL_INVALID_ARG_INDEX)
    ERODEM_CL_CASE(CL_INVALID_ARG_VALUE)
    ERODEM_CL_CASE(CL_INVALID_ARG_SIZE)
    ERODEM_CL_CASE(CL_INVALID_KERNEL_ARGS)
    ERODEM_CL_CASE(CL_INVALID_WORK_DIMENSION)
    ERODEM_CL_CASE(CL_INVALID_WORK_GROUP_SIZE)
    ERODEM_CL_CASE(CL_INVALID_WORK_ITEM_SIZE)
    ERODEM_CL_CASE(CL_INVALID_GLOBAL_OFFSET)
    ERODEM_CL_CASE(CL_INVALID_EVENT_WAIT_LIST)
    ERODEM_CL_CASE(CL_INVALID_EVENT)
    ERODEM_CL_CASE(CL_INVALID_OPERATION)
    ERODEM_CL_CASE(CL_INVALID_GL_OBJECT)
    ERODEM_CL_CASE(CL_INVALID_BUFFER_SIZE)
    ERODEM_CL_CASE(CL_INVALID_MIP_LEVEL)
    ERODEM_CL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    ERODEM_CL_CASE(CL_INVALID_PROPERTY)
    ERODEM_CL_CASE(CL_INVALID_IMAGE_DESCRIPTOR)
    ERODEM_CL_CASE(CL_INVALID_COMPILER_OPTIONS)
    ERODEM_CL_CASE(CL_INVALID_LINKER_OPTIONS)
    ERODEM_CL_CASE(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef ERODEM_CL_CASE
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "unknown OpenCL error";
  }
}

void check(cl_int code, const char* what) {
  if (code != CL_SUCCESS)
    throw Error(ExitCode::internal,
                fmt::format("OpenCL: {} failed: {} ({})", what, error_name(code), code));
}

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

template <class T>
T device_value(cl_device_id d, cl_device_info what) {
  T v{};
  check(clGetDeviceInfo(d, what, sizeof(T), &v, nullptr), "clGetDeviceInfo");
  return v;
}

struct DeviceEntry {
  cl_platform_id platform;
  cl_device_id device;
  ClDeviceInfo info;
};

/// Every device of every platform, in platform then device order; empty when none.
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

const EmbeddedSource* find_embedded(const std::string& name) {
  for (std::size_t k = 0; k < kEmbeddedSourceCount; ++k)
    if (name == kEmbeddedSources[k].name) return &kEmbeddedSources[k];
  return nullptr;
}

/// Appends `name` to `out`, expanding #include "x.h" lines (each file once: all carry
/// include guards).
void expand(const std::string& name, ProgramSource& out, std::set<std::string>& included,
            int depth) {
  const EmbeddedSource* src = find_embedded(name);
  if (!src) throw Error(ExitCode::internal, "OpenCL sources: '" + name + "' is not embedded");
  if (depth > 16) throw Error(ExitCode::internal, "OpenCL sources: #include nesting too deep");
  static const std::regex include_re(R"(^\s*#\s*include\s*"([^"]+)\"\s*$)");
  std::istringstream in(src->text);
  std::string line;
  int number = 0;
  auto emit = [&](const std::string& text, int at) {
    out.text += text;
    out.text += '\n';
    out.origin.push_back({name, at});
  };
  while (std::getline(in, line)) {
    ++number;
    std::smatch m;
    if (std::regex_match(line, m, include_re)) {
      const std::string header = m[1].str();
      if (!included.insert(header).second) {
        emit("/* " + header + ": already included */", number);
        continue;
      }
      emit("/* ---- begin " + header + " (included from " + name + ") ---- */", number);
      expand(header, out, included, depth + 1);
      emit("/* ---- end " + header + " ---- */", number);
    } else {
      emit(line, number);
    }
  }
}

}  // namespace

ProgramSource assemble_program() {
  // What the reductions share, the process files in step order, then the reductions; every
  // other embedded .cl after.
  std::vector<std::string> order = {"reduce.cl",      "boundary.cl", "sources.cl",   "flow.cl",
                                    "water.cl",       "erosion.cl",  "transport.cl", "thermal.cl",
                                    "evaporation.cl", "edges.cl",    "stats.cl"};
  for (std::size_t k = 0; k < kEmbeddedSourceCount; ++k) {
    const std::string name = kEmbeddedSources[k].name;
    if (name.size() > 3 && name.compare(name.size() - 3, 3, ".cl") == 0 &&
        std::find(order.begin(), order.end(), name) == order.end())
      order.push_back(name);
  }
  ProgramSource out;
  std::set<std::string> included;
  for (const auto& name : order) {
    out.text += "/* ==== " + name + " ==== */\n";
    out.origin.push_back({name, 0});
    expand(name, out, included, 0);
  }
  return out;
}

std::string annotate_build_log(const std::string& log, const ProgramSource& src) {
  static const std::regex loc_re(R"(:(\d+):(\d+):)");
  std::istringstream in(log);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    out << line << '\n';
    std::smatch m;
    if (!std::regex_search(line, m, loc_re)) continue;
    const long n = std::stol(m[1].str());
    if (n < 1 || n > static_cast<long>(src.origin.size())) continue;
    const auto& o = src.origin[static_cast<std::size_t>(n - 1)];
    // The offending line, from the assembled text.
    std::size_t begin = 0;
    for (long k = 1; k < n && begin != std::string::npos; ++k) {
      begin = src.text.find('\n', begin);
      if (begin != std::string::npos) ++begin;
    }
    std::string text;
    if (begin != std::string::npos) {
      const auto end = src.text.find('\n', begin);
      text = src.text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    }
    out << "    --> " << o.file << ':' << o.line << ':' << m[2].str() << ": " << text << '\n';
  }
  return out.str();
}

namespace {

/// Builds the program on the runtime's device; throws Error(internal) with the annotated
/// build log on failure. ERODEM_OPENCL_DUMP=dir writes the source and options there.
void build_program(Runtime& rt) {
  const ProgramSource src = assemble_program();
  if (const char* dir = std::getenv("ERODEM_OPENCL_DUMP"); dir && *dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    std::ofstream(std::filesystem::path(dir) / "erodem_program.cl") << src.text;
    std::ofstream(std::filesystem::path(dir) / "erodem_build_options.txt") << rt.options << '\n';
  }
  const char* text = src.text.c_str();
  const std::size_t length = src.text.size();
  cl_int err = CL_SUCCESS;
  rt.program = Program(clCreateProgramWithSource(rt.context.get(), 1, &text, &length, &err));
  check(err, "clCreateProgramWithSource");
  cl_device_id device = rt.device;
  err = clBuildProgram(rt.program.get(), 1, &device, rt.options.c_str(), nullptr, nullptr);
  if (err != CL_SUCCESS) {
    std::size_t size = 0;
    std::string log;
    if (clGetProgramBuildInfo(rt.program.get(), device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size) ==
            CL_SUCCESS &&
        size > 0) {
      log.resize(size);
      clGetProgramBuildInfo(rt.program.get(), device, CL_PROGRAM_BUILD_LOG, size, log.data(),
                            nullptr);
      while (!log.empty() && log.back() == '\0') log.pop_back();
    }
    rt.program.reset();
    throw Error(ExitCode::internal,
                fmt::format("OpenCL: building the kernels for '{} / {}' failed: {} ({}); options "
                            "'{}'; CL_PROGRAM_BUILD_LOG:\n{}",
                            rt.info.platform, rt.info.device, error_name(err), err, rt.options,
                            annotate_build_log(log, src)));
  }
}

}  // namespace

std::size_t whole_row_group(std::size_t W, std::size_t limit) {
  const std::size_t cap = std::min<std::size_t>(limit, 1024);  // ERODEM_CELL_GROUP_MAX
  for (std::size_t d = std::min(W, cap); d > 1; --d)
    if (W % d == 0) return d;
  return 1;
}

std::shared_ptr<Runtime> runtime_for(const std::string& selector, std::size_t row_width) {
  static std::mutex mutex;
  static std::map<std::pair<cl_device_id, bool>, std::shared_ptr<Runtime> > cache;
  const auto devices = enumerate_devices();
  if (devices.empty())
    throw Error(ExitCode::usage,
                "backend 'opencl': no OpenCL platform or device found (install an OpenCL "
                "driver, e.g. pocl-opencl-icd or the GPU vendor's, or use --backend cpu)");
  const DeviceEntry* chosen = nullptr;
  if (!selector.empty()) {
    for (const auto& d : devices)
      if (opencl_selector_matches(d.info, selector)) {
        chosen = &d;
        break;
      }
    if (!chosen)
      throw Error(ExitCode::usage,
                  fmt::format("ERODEM_OPENCL_DEVICE='{}': no OpenCL device matches "
                              "'<platform>:<device>'; devices: {}",
                              selector, describe(devices)));
  } else {
    for (const auto& d : devices)
      if (d.info.gpu()) {
        chosen = &d;
        break;
      }
    if (!chosen) chosen = &devices.front();
  }

  // Whole rows on CPU devices (PoCL vectorises across a row's work-items only where no
  // per-work-item condition guards the loads), unless a tuning size is set.
  const char* wg_env = std::getenv("ERODEM_OPENCL_WG");
  const bool whole_rows = chosen->info.type == "CPU" && !(wg_env && *wg_env) &&
                          whole_row_group(row_width, chosen->info.max_work_group) >=
                              std::min<std::size_t>(32, row_width);
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{chosen->device, whole_rows}];
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
  const auto fp = device_value<cl_device_fp_config>(rt->device, CL_DEVICE_SINGLE_FP_CONFIG);
  if (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT)
    rt->options += " -cl-fp32-correctly-rounded-divide-sqrt";
  build_program(*rt);
  slot = rt;
  return rt;
}

// ---- the backend ----------------------------------------------------------------------

namespace {

/// Sets kernel arguments in order.
inline void set_arg(cl_kernel k, cl_uint index, const Buffer& b) {
  cl_mem m = b.get();
  check(clSetKernelArg(k, index, sizeof(cl_mem), &m), "clSetKernelArg");
}
template <class T>
inline void set_arg(cl_kernel k, cl_uint index, const T& v) {
  static_assert(std::is_arithmetic_v<T>, "kernel arguments: buffers or numbers");
  check(clSetKernelArg(k, index, sizeof(T), &v), "clSetKernelArg");
}
template <class... Args>
void set_args(cl_kernel k, const Args&... args) {
  cl_uint index = 0;
  (set_arg(k, index++, args), ...);
}

constexpr std::size_t kReduceMax = 256;      // ERODEM_REDUCE_MAX of stats.cl
constexpr std::size_t kCellGroupMax = 1024;  // ERODEM_CELL_GROUP_MAX of reduce.cl
constexpr std::size_t kReduceGroupsMax = 1024;
constexpr std::size_t kTallySlots = 9;  // ERODEM_TALLY_SLOTS of reduce.cl
constexpr int kTallyExchange = 0;       // ERODEM_TALLY_EXCHANGE of reduce.cl
constexpr int kTallySediment = 2;       // ERODEM_TALLY_SEDIMENT of reduce.cl
// one bit per slot of reduce.cl (1 << ERODEM_TALLY_*), then the transport change
constexpr unsigned kExchangeBit = 1u << 0, kClippedBit = 1u << 1, kSedimentBit = 1u << 2,
                   kEvaporatedBit = 1u << 3, kWaterGivenBit = 1u << 4, kErodedBit = 1u << 5,
                   kDepositedBit = 1u << 6, kSedimentGivenBit = 1u << 7, kThermalBit = 1u << 8,
                   kTallyBits = (1u << kTallySlots) - 1, kChangeBit = 1u << kTallySlots;

/// A size from the environment (the tuning variable ERODEM_OPENCL_WG), else `fallback`. Where
/// the kernels are built for rounded launches, the cell kernels' work-group is ERODEM_OPENCL_WG
/// rounded down to a power of two, by default 64 on CPU devices and 128 on others, one row high;
/// CPU devices launch whole rows (a divisor of the row) unless ERODEM_OPENCL_WG is set.
std::size_t env_size(const char* name, std::size_t fallback) {
  if (const char* env = std::getenv(name); env && *env) {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1) return static_cast<std::size_t>(v);
  }
  return fallback;
}

}  // namespace

OpenClBackend::OpenClBackend(const Terrain& terrain, const Params& params,
                             const std::string& selector)
    : params_(params),
      nx_(terrain.grid.nx),
      ny_(terrain.grid.ny),
      W_(terrain.grid.nx + 2),
      H_(terrain.grid.ny + 2) {
  if (params.numerics.precision == Precision::float64)
    throw Error(ExitCode::config,
                "numerics.precision: the opencl backend runs float32 (the float64 reference "
                "runs on the cpu backend: --backend cpu)");
  const auto& g = terrain.grid;
  g.validate();
  n_ = static_cast<std::size_t>(W_) * H_;
  if (n_ > static_cast<std::size_t>(std::numeric_limits<cl_int>::max()))
    throw Error(ExitCode::data, fmt::format("backend 'opencl': a grid of {} x {} is too large "
                                            "(at most 2^31 padded cells)",
                                            nx_, ny_));
  const PaddedState state = build_padded_state(terrain, params);

  rt_ = runtime_for(selector, static_cast<std::size_t>(W_));
  cl_int err = CL_SUCCESS;
  queue_ = Queue(clCreateCommandQueue(rt_->context.get(), rt_->device, 0, &err));
  check(err, "clCreateCommandQueue");
  acc_size_ = rt_->fp64 ? sizeof(double) : sizeof(float);

  // ---- the host state: the same padded state the CPU reference starts from ----
  auto to_real = [](const std::vector<double>& v) { return std::vector<Real>(v.begin(), v.end()); };
  const std::vector<Real> dx = to_real(state.dx), dy = to_real(state.dy),
                          area = to_real(state.area);
  area_host_.assign(area.begin(), area.end());
  const std::vector<cl_uchar> kind(state.kind.begin(), state.kind.end());
  const std::vector<Real> bed_r = to_real(state.bed), depth_r = to_real(state.depth),
                          zeros(n_, Real(0));

  // ---- the device state ----
  kind_ = upload(kind);
  dx_ = upload(dx);
  dy_ = upload(dy);
  area_ = upload(area);
  bed_ = upload(bed_r);
  bed_next_ = upload(bed_r);
  bed0_ = upload(bed_r);
  bed_residual_ = upload(std::vector<Real>(bed_r.size(), Real(0)));
  depth_ = upload(depth_r);
  depth_next_ = upload(depth_r);
  sediment_ = upload(zeros);
  sediment_next_ = upload(zeros);
  for (int k = 0; k < 4; ++k) {
    flux_[k] = upload(zeros);
    flux_next_[k] = upload(zeros);
  }
  face_x_ = upload(zeros);
  face_y_ = upload(zeros);
  velocity_x_ = upload(zeros);
  velocity_y_ = upload(zeros);
  thermal_share_ = upload(zeros);
  wetness_ = upload(depth_r);
  manning_ = upload(to_real(state.manning));
  hardness_ = upload(to_real(state.hardness));
  rain_factor_ = upload(to_real(state.rain_factor));

  // Reductions: a power of two of at most 256 work-items per group, fitting every reduction
  // kernel; a fixed number of groups for this grid, so the sums do not depend on timing.
  std::size_t limit = std::min(kReduceMax, rt_->max_work_group);
  for (const char* name : {"reduce_tallies", "reduce_change", "stats_rows"}) {
    std::size_t wg = 0;
    check(clGetKernelWorkGroupInfo(kernel(name), rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg),
                                   &wg, nullptr),
          "clGetKernelWorkGroupInfo");
    limit = std::min(limit, wg);
  }
  reduce_local_ = 1;
  while (reduce_local_ * 2 <= limit) reduce_local_ *= 2;
  reduce_groups_ =
      std::clamp<std::size_t>((n_ + reduce_local_ - 1) / reduce_local_, 1, kReduceGroupsMax);
  partial_b_ = make_buffer(reduce_groups_ * acc_size_);

  // Cell kernels: work-groups of (local_x_, 1) that every cell kernel accepts: a divisor
  // of the row by one row (whole rows), else powers of two; a fixed number of groups for this
  // grid (the tallies' partials, summed in a fixed order). Where a kernel accepts less than the
  // device's maximum, the whole-row divisor may be small: still correct, slower.
  const bool cpu = rt_->info.type == "CPU";
  std::size_t cell_limit = std::min(kCellGroupMax, rt_->max_work_group);
  for (const char* name :
       {"sources_rain", "flow_pipes", "flow_pipes_interior", "flow_local_inertial_faces",
        "flow_local_inertial_faces_x_interior", "flow_local_inertial_faces_y_interior",
        "flow_local_inertial_split", "flow_local_inertial_split_interior", "water_update",
        "erosion", "transport_conservative", "transport_semi_lagrangian", "thermal_share",
        "thermal_apply", "evaporation", "field_stats", "edge_tallies"}) {
    std::size_t wg = 0;
    check(clGetKernelWorkGroupInfo(kernel(name), rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg),
                                   &wg, nullptr),
          "clGetKernelWorkGroupInfo");
    cell_limit = std::min(cell_limit, wg);
  }
  auto pow2_at_most = [](std::size_t v) {
    std::size_t p = 1;
    while (p * 2 <= v) p *= 2;
    return p;
  };
  if (rt_->whole_rows) {
    // the program was built for it: a local size that divides the row (any divisor keeps
    // the kernels correct; the largest is the fastest)
    local_x_ = whole_row_group(static_cast<std::size_t>(W_), cell_limit);
  } else {
    local_x_ = pow2_at_most(std::min(cell_limit, env_size("ERODEM_OPENCL_WG", cpu ? 64 : 128)));
  }
  groups_x_ = (static_cast<std::size_t>(W_) + local_x_ - 1) / local_x_;
  interior_groups_ = groups_x_ * static_cast<std::size_t>(H_ - 2);
  partial_a_ = make_buffer(interior_groups_ * 5 * acc_size_);  // field_stats, per group
  partial_cells_ = make_buffer(interior_groups_ * 3 * sizeof(cl_long));
  row_sums_ = make_buffer(static_cast<std::size_t>(H_ - 2) * 6 * acc_size_);  // stats_rows
  row_cells_ = make_buffer(static_cast<std::size_t>(H_ - 2) * 3 * sizeof(cl_long));
  // The active cells beside a ghost, row-major: the only ones with a water exchange or a
  // sediment outflow through the domain's faces (edges.cl). The kinds never change.
  std::vector<cl_int> edges;
  for (int y = 1; y < H_ - 1; ++y)
    for (int x = 1; x < W_ - 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W_;
      if (kind[i] != ERODEM_CELL_ACTIVE) continue;
      if (kind[i - 1] != ERODEM_CELL_ACTIVE || kind[i + 1] != ERODEM_CELL_ACTIVE ||
          kind[i - W_] != ERODEM_CELL_ACTIVE || kind[i + W_] != ERODEM_CELL_ACTIVE)
        edges.push_back(static_cast<cl_int>(i));
    }
  edge_count_ = edges.size();
  edge_cells_ = upload(edges);
  edge_local_ = pow2_at_most(std::min<std::size_t>(cell_limit, 64));
  edge_groups_ = std::max<std::size_t>(1, (edge_count_ + edge_local_ - 1) / edge_local_);
  // Every slot holds tally_stride_ partials; what no kernel writes stays 0.
  tally_stride_ = std::max(interior_groups_, edge_groups_);
  const std::vector<unsigned char> no_partials(kTallySlots * tally_stride_ * acc_size_, 0);
  tally_partials_ = upload(no_partials);
  tally_sums_ = make_buffer(kTallySlots * acc_size_);
  run_boundary();
}

std::string OpenClBackend::device() const {
  return rt_->info.platform + " / " + rt_->info.device;
}

// Field buffers start at different offsets modulo 4 KiB (stagger.hpp): each one of at least
// kStaggerMin bytes is a sub-buffer of a parent kStaggerPeriod bytes longer, its origin at
// the next slot's offset (rounded to the device's base alignment). PoCL at 4096^2, four bench
// runs alternating with a build without it: full local-inertial step 190.8 -> 165.6 ms (flow
// 67.0 -> 58.0, transport 21.9 -> 18.4, water 22.9 -> 20.6).
Buffer OpenClBackend::make_buffer(std::size_t bytes, const void* data) {
  cl_int err = CL_SUCCESS;
  bytes = std::max<std::size_t>(bytes, 1);
  const std::size_t align = rt_->base_align;
  // The staggering is only for speed: a buffer that would not fit with the extra 4 KiB, or a
  // sub-buffer the device refuses, gets a plain buffer.
  if (bytes >= kStaggerMin && align < kStaggerPeriod && bytes + kStaggerPeriod <= rt_->max_alloc) {
    const std::size_t offset = stagger_offset(stagger_next_++, align);
    Buffer parent(clCreateBuffer(rt_->context.get(), CL_MEM_READ_WRITE, bytes + kStaggerPeriod,
                                 nullptr, &err));
    if (err == CL_SUCCESS) {
      const cl_buffer_region region{offset, bytes};
      // The sub-buffer keeps its parent alive (OpenCL 1.2, clReleaseMemObject).
      Buffer b(clCreateSubBuffer(parent.get(), CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION,
                                 &region, &err));
      if (err == CL_SUCCESS) {
        if (data)
          check(clEnqueueWriteBuffer(queue_.get(), b.get(), CL_TRUE, 0, bytes, data, 0, nullptr,
                                     nullptr),
                "clEnqueueWriteBuffer");
        return b;
      }
    }
  }
  const cl_mem_flags flags = CL_MEM_READ_WRITE | (data ? CL_MEM_COPY_HOST_PTR : 0);
  Buffer b(clCreateBuffer(rt_->context.get(), flags, bytes, const_cast<void*>(data), &err));
  check(err, "clCreateBuffer");
  return b;
}

cl_kernel OpenClBackend::kernel(const char* name) {
  for (auto& [n, k] : kernels_)
    if (n == name) return k.get();
  cl_int err = CL_SUCCESS;
  Kernel k(clCreateKernel(rt_->program.get(), name, &err));
  check(err, fmt::format("clCreateKernel({})", name).c_str());
  kernels_.emplace_back(name, std::move(k));
  return kernels_.back().second.get();
}

void OpenClBackend::launch_interior(cl_kernel k) {
  launch_rows(k, 1, H_ - 1);
}

void OpenClBackend::launch_rows(cl_kernel k, int y0, int y1) {
  if (y1 <= y0) return;
  const std::size_t offset[2] = {0, static_cast<std::size_t>(y0)};
  const std::size_t global[2] = {groups_x_ * local_x_, static_cast<std::size_t>(y1 - y0)};
  const std::size_t local[2] = {local_x_, 1};
  check(clEnqueueNDRangeKernel(queue_.get(), k, 2, offset, global, local, 0, nullptr, nullptr),
        "clEnqueueNDRangeKernel");
}

void OpenClBackend::launch_edge_tallies(int slot, Real dt) {
  if (edge_count_ == 0) return;
  cl_kernel k = kernel("edge_tallies");
  set_args(k, cl_int{W_}, kind_, edge_cells_, static_cast<cl_int>(edge_count_), flux_[0], flux_[1],
           flux_[2], flux_[3], sediment_, depth_next_, dt, cl_int{slot}, tally_partials_,
           static_cast<cl_int>(tally_stride_));
  const std::size_t global = edge_groups_ * edge_local_, local = edge_local_;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, &local, 0, nullptr, nullptr),
        "clEnqueueNDRangeKernel(edge_tallies)");
}

void OpenClBackend::launch_reduction(cl_kernel k, std::size_t groups) {
  const std::size_t global = groups * reduce_local_, local = reduce_local_;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, &local, 0, nullptr, nullptr),
        "clEnqueueNDRangeKernel");
}

void OpenClBackend::read(const Buffer& b, std::size_t bytes, void* dst, bool blocking) {
  check(clEnqueueReadBuffer(queue_.get(), b.get(), blocking ? CL_TRUE : CL_FALSE, 0, bytes, dst, 0,
                            nullptr, nullptr),
        "clEnqueueReadBuffer");
}

std::vector<double> OpenClBackend::acc_values(const std::vector<unsigned char>& raw,
                                              std::size_t count) const {
  std::vector<double> out(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (acc_size_ == sizeof(double)) {
      std::memcpy(&out[k], raw.data() + k * sizeof(double), sizeof(double));
    } else {
      float f;
      std::memcpy(&f, raw.data() + k * sizeof(float), sizeof(float));
      out[k] = f;
    }
  }
  return out;
}

void OpenClBackend::defer(StepTally& tally, unsigned bits) {
  // A tally for another StepTally, or one whose slot is still pending: deliver first.
  if (pending_ && (pending_tally_ != &tally || (pending_ & bits))) flush_tallies();
  pending_tally_ = &tally;
  pending_ |= bits;
}

void OpenClBackend::enqueue_tally_reduction() {
  if (!(pending_ & kTallyBits)) return;
  cl_kernel k = kernel("reduce_tallies");
  set_args(k, static_cast<cl_int>(tally_stride_), tally_partials_, tally_sums_);
  launch_reduction(k, kTallySlots);
}

void OpenClBackend::deliver_tallies() {
  if (!pending_ || !pending_tally_) {
    pending_ = 0;
    return;
  }
  StepTally& t = *pending_tally_;
  if (pending_ & kTallyBits) {
    const auto v = acc_values(tally_raw_, kTallySlots);
    if (pending_ & kExchangeBit)
      t.boundary_water_out += static_cast<double>(pending_water_dt_) * v[0];
    if (pending_ & kClippedBit) t.clipped += v[1];
    if (pending_ & kSedimentBit) t.sediment_out += v[2];
    if (pending_ & kEvaporatedBit) t.evaporated += v[3];
    if (pending_ & kWaterGivenBit) t.water_exchanged += v[4];
    if (pending_ & kErodedBit) t.eroded += v[5];
    if (pending_ & kDepositedBit) t.deposited += v[6];
    if (pending_ & kSedimentGivenBit) t.sediment_exchanged += v[7];
    if (pending_ & kThermalBit) t.thermal_moved += v[8];
  }
  if (pending_ & kChangeBit) {
    double change = 0.0;
    for (double v : acc_values(change_raw_, reduce_groups_)) change += v;
    t.transport_change += change;
  }
  pending_ = 0;
  pending_tally_ = nullptr;
}

void OpenClBackend::flush_tallies() {
  if (!pending_) return;
  enqueue_tally_reduction();
  tally_raw_.resize(kTallySlots * acc_size_);
  change_raw_.resize(reduce_groups_ * acc_size_);
  if (pending_ & kChangeBit) read(partial_b_, change_raw_.size(), change_raw_.data(), false);
  if (pending_ & kTallyBits) read(tally_sums_, tally_raw_.size(), tally_raw_.data(), false);
  check(clFinish(queue_.get()), "clFinish");
  deliver_tallies();
}

void OpenClBackend::run(Process p, const StepInputs& in, StepTally& tally) {
  const Real dt = static_cast<Real>(in.dt);
  switch (p) {
    case Process::boundary:
      run_boundary();
      break;
    case Process::sources:
      run_sources(in);
      break;
    case Process::flow:
      run_flow(dt);
      break;
    case Process::water:
      run_water(dt, tally);
      break;
    case Process::erosion:
      run_erosion(dt, tally);
      break;
    case Process::transport:
      run_transport(dt, tally);
      break;
    case Process::thermal:
      run_thermal(dt, tally);
      break;
    case Process::evaporation:
      run_evaporation(dt, tally);
      break;
  }
}

void OpenClBackend::run_boundary() {
  cl_kernel k = kernel("boundary_fill");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_,
           static_cast<Real>(params_.boundary.sea_level));
  const std::size_t global = 2 * static_cast<std::size_t>(W_ - 2 + H_ - 2);
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, nullptr, 0, nullptr, nullptr),
        "clEnqueueNDRangeKernel(boundary_fill)");
}

void OpenClBackend::run_sources(const StepInputs& in) {
  const Real dt = static_cast<Real>(in.dt);
  const Real rate = static_cast<Real>(in.rain_rate);
  if (rate != Real(0)) {
    cl_kernel k = kernel("sources_rain");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, depth_, rain_factor_, dt, rate);
    launch_interior(k);
  }
  if (in.points.empty()) return;
  std::vector<cl_int> cells;
  std::vector<Real> amounts;
  for (const auto& p : in.points) {
    const int x = static_cast<int>(p.cell % nx_) + 1, y = static_cast<int>(p.cell / nx_) + 1;
    cells.push_back(x + y * W_);
    amounts.push_back(static_cast<Real>(p.volume / area_host_[y]));
  }
  // The previous upload (if any) may still read the host vectors.
  if (points_written_) {
    cl_event e = points_written_.get();
    check(clWaitForEvents(1, &e), "clWaitForEvents");
    points_written_.reset();
  }
  point_cells_host_ = std::move(cells);
  point_amounts_host_ = std::move(amounts);
  const auto& cells_h = point_cells_host_;
  const auto& amounts_h = point_amounts_host_;
  if (cells_h.size() > point_capacity_) {
    point_capacity_ = std::max<std::size_t>(cells_h.size(), 2 * point_capacity_);
    point_cells_ = make_buffer(point_capacity_ * sizeof(cl_int));
    point_amounts_ = make_buffer(point_capacity_ * sizeof(Real));
  }
  // Non-blocking uploads (the queue is in order): the step does not wait for the device.
  check(clEnqueueWriteBuffer(queue_.get(), point_cells_.get(), CL_FALSE, 0,
                             cells_h.size() * sizeof(cl_int), cells_h.data(), 0, nullptr, nullptr),
        "clEnqueueWriteBuffer");
  cl_event written = nullptr;
  check(
      clEnqueueWriteBuffer(queue_.get(), point_amounts_.get(), CL_FALSE, 0,
                           amounts_h.size() * sizeof(Real), amounts_h.data(), 0, nullptr, &written),
      "clEnqueueWriteBuffer");
  points_written_ = Event(written);
  cl_kernel k = kernel("sources_points");
  set_args(k, depth_, point_cells_, point_amounts_, static_cast<cl_int>(cells_h.size()));
  const std::size_t one = 1;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &one, nullptr, 0, nullptr, nullptr),
        "clEnqueueNDRangeKernel(sources_points)");
}

void OpenClBackend::run_flow(Real dt) {
  const auto& f = params_.flow;
  const Real g = static_cast<Real>(f.gravity);
  if (f.scheme == FlowScheme::pipes) {
    // The interior rows by a kernel without clamping, the first and last row by the general one.
    for (const char* name : {"flow_pipes_interior", "flow_pipes"})
      set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, dx_, dy_, area_, flux_[0],
               flux_[1], flux_[2], flux_[3], flux_next_[0], flux_next_[1], flux_next_[2],
               flux_next_[3], dt, g, static_cast<Real>(f.pipe_area),
               static_cast<Real>(f.pipe_length));
    launch_interior(kernel("flow_pipes_interior"));
    launch_rows(kernel("flow_pipes"), 0, 1);
    launch_rows(kernel("flow_pipes"), H_ - 1, H_);
  } else {
    // Each face once (face pass), then split into the cells' outflows (cell pass); the
    // interior rows by kernels that need no clamping (they vectorise on CPU devices), the
    // edge rows by the general ones. H >= 3.
    const Real theta = static_cast<Real>(f.theta),
               dry = static_cast<Real>(params_.numerics.dry_depth);
    for (const char* name : {"flow_local_inertial_faces_x_interior",
                             "flow_local_inertial_faces_y_interior", "flow_local_inertial_faces"})
      set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, manning_, dx_, dy_,
               flux_[0], flux_[1], flux_[2], flux_[3], face_x_, face_y_, dt, g, theta, dry);
    launch_rows(kernel("flow_local_inertial_faces_x_interior"), 1, H_ - 2);
    launch_rows(kernel("flow_local_inertial_faces_y_interior"), 1, H_ - 2);
    launch_rows(kernel("flow_local_inertial_faces"), 0, 1);
    launch_rows(kernel("flow_local_inertial_faces"), H_ - 2, H_);
    for (const char* name : {"flow_local_inertial_split_interior", "flow_local_inertial_split"})
      set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, depth_, area_, face_x_, face_y_,
               flux_next_[0], flux_next_[1], flux_next_[2], flux_next_[3], dt);
    launch_rows(kernel("flow_local_inertial_split_interior"), 1, H_ - 1);
    launch_rows(kernel("flow_local_inertial_split"), 0, 1);
    launch_rows(kernel("flow_local_inertial_split"), H_ - 1, H_);
  }
  std::swap(flux_, flux_next_);
}

void OpenClBackend::run_water(Real dt, StepTally& tally) {
  cl_kernel k = kernel("water_update");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, depth_next_, flux_[0], flux_[1],
           flux_[2], flux_[3], dx_, dy_, area_, velocity_x_, velocity_y_, dt,
           static_cast<Real>(params_.numerics.velocity_min_depth), tally_partials_,
           static_cast<cl_int>(tally_stride_));
  defer(tally, kExchangeBit | kClippedBit | kWaterGivenBit);
  pending_water_dt_ = dt;
  launch_interior(k);
  launch_edge_tallies(kTallyExchange, dt);
  // depth_next_ keeps the depth the water update started from (after this step's sources):
  // conservative transport needs it.
  std::swap(depth_, depth_next_);
}

void OpenClBackend::run_erosion(Real dt, StepTally& tally) {
  const auto& e = params_.erosion;
  const Real bedrock = e.bedrock_level ? static_cast<Real>(*e.bedrock_level)
                                       : -std::numeric_limits<Real>::infinity();
  cl_kernel k = kernel("erosion");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, bed_next_, bed_residual_, sediment_, depth_,
           velocity_x_, velocity_y_, hardness_, dx_, dy_, area_, dt,
           static_cast<Real>(e.sediment_capacity), static_cast<Real>(e.dissolving_rate),
           static_cast<Real>(e.deposition_rate), static_cast<Real>(e.min_tilt),
           static_cast<Real>(e.min_depth), bedrock, tally_partials_,
           static_cast<cl_int>(tally_stride_));
  defer(tally, kErodedBit | kDepositedBit);
  launch_interior(k);
  std::swap(bed_, bed_next_);
}

void OpenClBackend::run_transport(Real dt, StepTally& tally) {
  if (params_.transport.scheme == TransportScheme::conservative) {
    cl_kernel k = kernel("transport_conservative");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, sediment_, sediment_next_, depth_next_, flux_[0],
             flux_[1], flux_[2], flux_[3], area_, dt, tally_partials_,
             static_cast<cl_int>(tally_stride_));
    defer(tally, kSedimentBit | kSedimentGivenBit);
    launch_interior(k);
    launch_edge_tallies(kTallySediment, dt);  // reads sediment_ before the swap
  } else {
    cl_kernel k = kernel("transport_semi_lagrangian");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, sediment_, sediment_next_, velocity_x_, velocity_y_,
             dx_, dy_, dt);
    launch_interior(k);
    cl_kernel r = kernel("reduce_change");
    set_args(r, cl_int{W_}, cl_int{H_}, kind_, sediment_next_, sediment_, area_, partial_b_);
    defer(tally, kChangeBit);
    launch_reduction(r, reduce_groups_);
  }
  std::swap(sediment_, sediment_next_);
}

void OpenClBackend::run_thermal(Real dt, StepTally& tally) {
  const double pi = 3.14159265358979323846;
  const Real tan_talus = static_cast<Real>(std::tan(params_.thermal.talus_angle * pi / 180.0));
  const Real rate = static_cast<Real>(params_.thermal.rate);
  cl_kernel share = kernel("thermal_share");
  set_args(share, cl_int{W_}, cl_int{H_}, kind_, bed_, dx_, dy_, area_, thermal_share_, dt, rate,
           tan_talus);
  launch_interior(share);
  cl_kernel apply = kernel("thermal_apply");
  set_args(apply, cl_int{W_}, cl_int{H_}, kind_, bed_, bed_residual_, thermal_share_, dx_, dy_,
           area_, bed_next_, tan_talus, tally_partials_, static_cast<cl_int>(tally_stride_));
  defer(tally, kThermalBit);
  launch_interior(apply);
  std::swap(bed_, bed_next_);
}

void OpenClBackend::run_evaporation(Real dt, StepTally& tally) {
  const Real rate = static_cast<Real>(params_.evaporation.rate);
  const Real tau = static_cast<Real>(params_.numerics.wetness_time);
  cl_kernel k = kernel("evaporation");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, depth_, wetness_, area_, dt, rate, tau,
           cl_int{rate > Real(0) ? 1 : 0}, tally_partials_, static_cast<cl_int>(tally_stride_));
  defer(tally, kEvaporatedBit);
  launch_interior(k);
}

void OpenClBackend::finish() {
  flush_tallies();
  check(clFinish(queue_.get()), "clFinish");
}

FieldStats OpenClBackend::stats() {
  cl_kernel k = kernel("field_stats");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, bed_residual_, depth_, sediment_, velocity_x_,
           velocity_y_, area_, partial_a_, partial_cells_);
  launch_interior(k);
  const int rows = H_ - 2;
  cl_kernel r = kernel("stats_rows");
  set_args(r, cl_int{W_}, cl_int{rows}, static_cast<cl_int>(groups_x_), partial_a_, partial_cells_,
           velocity_x_, velocity_y_, row_sums_, row_cells_);
  launch_reduction(r, (static_cast<std::size_t>(rows) + reduce_local_ - 1) / reduce_local_);
  // The step's tallies with the statistics: one wait per step (the queue is in order).
  enqueue_tally_reduction();
  tally_raw_.resize(kTallySlots * acc_size_);
  change_raw_.resize(reduce_groups_ * acc_size_);
  if (pending_ & kChangeBit) read(partial_b_, change_raw_.size(), change_raw_.data(), false);
  if (pending_ & kTallyBits) read(tally_sums_, tally_raw_.size(), tally_raw_.data(), false);
  std::vector<cl_long> cells(static_cast<std::size_t>(rows) * 3);
  read(row_cells_, cells.size() * sizeof(cl_long), cells.data(), false);
  stats_sums_raw_.resize(static_cast<std::size_t>(rows) * 6 * acc_size_);
  read(row_sums_, stats_sums_raw_.size(), stats_sums_raw_.data(), true);
  deliver_tallies();
  const auto sums = acc_values(stats_sums_raw_, static_cast<std::size_t>(rows) * 6);
  // Rows in order, with the rules of CpuBackend::stats: the max depth starts at 0 and a
  // later row takes it when larger (or when none has been taken); the max speed ranks the
  // rows by the squared speed; the first bad cell.
  FieldStats st;
  st.max_depth = 0.0;
  st.max_speed = 0.0;
  double best_v2 = -1;
  for (std::size_t y = 0; y < static_cast<std::size_t>(rows); ++y) {
    st.water_volume += sums[6 * y + 0];
    st.material_volume += sums[6 * y + 1];
    st.sediment_volume += sums[6 * y + 2];
    const double max_d = sums[6 * y + 3], max_v2 = sums[6 * y + 4];
    const std::int64_t arg_d = cells[3 * y + 0], arg_v = cells[3 * y + 1], bad = cells[3 * y + 2];
    if (max_d > st.max_depth || (st.max_depth_cell < 0 && arg_d >= 0)) {
      st.max_depth = std::max(0.0, max_d);
      st.max_depth_cell = arg_d;
    }
    if (arg_v >= 0 && (st.max_speed_cell < 0 || max_v2 > best_v2)) {
      best_v2 = max_v2;
      st.max_speed_cell = arg_v;
      st.max_speed = std::max(0.0, sums[6 * y + 5]);
    }
    if (st.bad_cell < 0 && bad >= 0) st.bad_cell = bad;
  }
  return st;
}

Buffer* OpenClBackend::field_buffer(FieldId id) {
  switch (id) {
    case FieldId::bed:
      return &bed_;
    case FieldId::water_depth:
      return &depth_;
    case FieldId::sediment:
      return &sediment_;
    case FieldId::velocity_x:
      return &velocity_x_;
    case FieldId::velocity_y:
      return &velocity_y_;
    case FieldId::flux_left:
      return &flux_[ERODEM_LEFT];
    case FieldId::flux_right:
      return &flux_[ERODEM_RIGHT];
    case FieldId::flux_top:
      return &flux_[ERODEM_TOP];
    case FieldId::flux_bottom:
      return &flux_[ERODEM_BOTTOM];
    case FieldId::hardness:
      return &hardness_;
    case FieldId::wetness:
      return &wetness_;
    case FieldId::manning_n:
      return &manning_;
    case FieldId::initial_bed:
      return &bed0_;
    case FieldId::bed_residual:
      return &bed_residual_;
    case FieldId::erosion:
      return nullptr;
  }
  return nullptr;
}

namespace {

/// The DEM cells (the padded raster without its halo) of a buffer, row-major (ny, nx).
std::vector<float> read_interior(cl_command_queue q, cl_mem b, int nx, int ny) {
  std::vector<float> out(static_cast<std::size_t>(nx) * ny);
  const std::size_t origin[3] = {sizeof(float), 1, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(ny), 1};
  check(clEnqueueReadBufferRect(q, b, CL_TRUE, origin, std::array<std::size_t, 3>{0, 0, 0}.data(),
                                region, (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                static_cast<std::size_t>(nx) * sizeof(float), 0, out.data(), 0,
                                nullptr, nullptr),
        "clEnqueueReadBufferRect");
  return out;
}

void write_interior(cl_command_queue q, cl_mem b, int nx, int ny, const std::vector<float>& v) {
  const std::size_t origin[3] = {sizeof(float), 1, 0};
  const std::size_t host_origin[3] = {0, 0, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(ny), 1};
  check(clEnqueueWriteBufferRect(q, b, CL_TRUE, origin, host_origin, region,
                                 (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                 static_cast<std::size_t>(nx) * sizeof(float), 0, v.data(), 0,
                                 nullptr, nullptr),
        "clEnqueueWriteBufferRect");
}

}  // namespace

std::vector<double> OpenClBackend::field(FieldId id) const {
  auto* self = const_cast<OpenClBackend*>(this);
  if (id == FieldId::erosion || id == FieldId::bed) {
    // the bed and the erosion include the bed's residual (exact in double)
    const auto b = read_interior(queue_.get(), bed_.get(), nx_, ny_);
    const auto lo = read_interior(queue_.get(), bed_residual_.get(), nx_, ny_);
    const auto b0 = id == FieldId::erosion ? read_interior(queue_.get(), bed0_.get(), nx_, ny_)
                                           : std::vector<float>();
    std::vector<double> out(b.size());
    for (std::size_t i = 0; i < b.size(); ++i)
      out[i] = id == FieldId::bed ? static_cast<double>(b[i]) + static_cast<double>(lo[i])
                                  : (static_cast<double>(b0[i]) - static_cast<double>(b[i])) -
                                        static_cast<double>(lo[i]);
    return out;
  }
  const auto v = read_interior(queue_.get(), self->field_buffer(id)->get(), nx_, ny_);
  return std::vector<double>(v.begin(), v.end());
}

void OpenClBackend::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  Buffer* dst = field_buffer(id);
  if (!dst) throw Error(ExitCode::usage, "field 'erosion' is derived and cannot be set");
  // Fields kept in two buffers get both, so the next step starts from the new values.
  Buffer* twin = id == FieldId::bed           ? &bed_next_
                 : id == FieldId::water_depth ? &depth_next_
                 : id == FieldId::sediment    ? &sediment_next_
                                              : nullptr;
  const std::vector<float> v(values.begin(), values.end());
  write_interior(queue_.get(), dst->get(), nx_, ny_, v);
  if (twin) write_interior(queue_.get(), twin->get(), nx_, ny_, v);
  if (id == FieldId::bed) {
    // a bed keeps what float cannot hold in its residual (set bed_residual after the bed)
    std::vector<float> lo(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      lo[i] = static_cast<float>(values[i] - static_cast<double>(v[i]));
    write_interior(queue_.get(), bed_residual_.get(), nx_, ny_, lo);
  }
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

std::unique_ptr<Backend> make_opencl_backend(const Terrain& terrain, const Params& params) {
  const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
  return std::make_unique<opencl::OpenClBackend>(terrain, params, env ? env : "");
}

}  // namespace erodem

#endif
