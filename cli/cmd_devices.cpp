// `erodem devices`: the OpenCL platforms and devices, the CPU reference, and which one
// `--backend auto` picks and why.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif
#ifdef ERODEM_HAVE_OPENCL
#include <CL/cl.h>
#endif

#include "commands.hpp"
#include "erodem/backends.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace {

struct DevicesOptions {
  bool json = false;
};

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        auto s = line.substr(colon + 1);
        s.erase(0, s.find_first_not_of(" \t"));
        return s;
      }
    }
  return "unknown CPU";
}

int cpu_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

std::string gib(std::uint64_t bytes) {
  return fmt::format("{:.1f} GiB", static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0));
}

int devices(const DevicesOptions& o) {
  const auto list = list_opencl_devices();
  const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
  const std::string selector = env ? env : "";
  const BackendChoice choice = auto_backend_choice(list, selector);
  const CpuIsaInfo isa = cpu_isa_info();
  const std::string cpu = cpu_model();
  const int threads = cpu_threads();
#ifdef ERODEM_HAVE_OPENCL
  const bool built = true;
#else
  const bool built = false;
#endif
  auto chosen_name = [&] {
    if (choice.backend == "opencl") return list[static_cast<std::size_t>(choice.device)].label();
    if (choice.backend == "cpu") return std::string("CPU reference");
    return std::string("none");
  };

  if (o.json) {
    std::printf("{\"opencl_built\": %s, \"erodem_opencl_device\": %s,\n \"opencl_devices\": [",
                built ? "true" : "false", env ? json_string(selector).c_str() : "null");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const auto& d = list[k];
      std::printf(
          "%s\n  {\"index\": %zu, \"platform\": %s, \"vendor\": %s, \"device\": %s, "
          "\"type\": %s, \"compute_units\": %u, \"global_memory_bytes\": %llu, "
          "\"max_work_group_size\": %s, \"fp64\": %s, \"version\": %s, \"driver\": %s, "
          "\"auto\": %s}",
          k == 0 ? "" : ",", k, json_string(d.platform).c_str(), json_string(d.vendor).c_str(),
          json_string(d.device).c_str(), json_string(d.type).c_str(), d.compute_units,
          static_cast<unsigned long long>(d.global_memory),
          d.max_work_group ? std::to_string(d.max_work_group).c_str() : "null",
          d.fp64 ? "true" : "false", json_string(d.version).c_str(), json_string(d.driver).c_str(),
          choice.backend == "opencl" && choice.device == static_cast<int>(k) ? "true" : "false");
    }
    std::printf(
        "%s],\n \"cpu_reference\": {\"device\": %s, \"threads\": %d, \"precisions\": "
        "[\"float32\", \"float64\"], \"isa\": %s, \"isa_built\": %s, \"auto\": %s},\n",
        list.empty() ? "" : "\n ", json_string(cpu).c_str(), threads,
        json_string(isa.level).c_str(), json_string(isa.built).c_str(),
        choice.backend == "cpu" ? "true" : "false");
    std::printf(
        " \"auto\": {\"backend\": %s, \"device\": %s, \"reason\": %s, \"float64\": \"cpu\"}}\n",
        choice.backend.empty() ? "null" : json_string(choice.backend).c_str(),
        json_string(chosen_name()).c_str(), json_string(choice.reason).c_str());
    return 0;
  }

  if (!built) {
    std::printf("OpenCL: not built in (ERODEM_OPENCL=OFF)\n");
  } else if (list.empty()) {
    std::printf("OpenCL: no platform or device found\n");
  } else {
    std::printf("OpenCL devices:\n");
    std::string platform;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const auto& d = list[k];
      if (d.platform != platform) {
        std::printf("  platform %s (%s)\n", d.platform.c_str(), d.vendor.c_str());
        platform = d.platform;
      }
      const bool picked = choice.backend == "opencl" && choice.device == static_cast<int>(k);
      std::printf("  %s [%zu] %s\n", picked ? "*" : " ", k, d.device.c_str());
      std::printf("        %s, %u compute units, %s global memory, max work-group %s, fp64 %s\n",
                  d.type.c_str(), d.compute_units, gib(d.global_memory).c_str(),
                  d.max_work_group ? std::to_string(d.max_work_group).c_str() : "?",
                  d.fp64 ? "yes" : "no");
      if (!d.version.empty())
        std::printf("        %s, driver %s\n", d.version.c_str(), d.driver.c_str());
    }
  }
  std::printf(
      "CPU reference:\n  %s [cpu] %s, %d OpenMP thread%s, float32 and float64, %s (built: "
      "%s; ERODEM_CPU_ISA chooses)\n",
      choice.backend == "cpu" ? "*" : " ", cpu.c_str(), threads, threads == 1 ? "" : "s",
      isa.level.c_str(), isa.built.c_str());
  std::printf("ERODEM_OPENCL_DEVICE: %s\n",
              env ? ("'" + selector + "'").c_str() : "unset (\"<platform>:<device>\" substrings)");
  if (choice.backend.empty())
    std::printf("auto: fails: %s\n", choice.reason.c_str());
  else
    std::printf(
        "auto picks: %s on %s (%s); numerics.precision = float64 runs on the CPU "
        "reference\n",
        choice.backend.c_str(), chosen_name().c_str(), choice.reason.c_str());
  return 0;
}

}  // namespace

Action add_devices(CLI::App& app) {
  auto o = std::make_shared<DevicesOptions>();
  auto* sub = app.add_subcommand("devices", "OpenCL platforms and devices, and what auto picks");
  sub->add_flag("--json", o->json, "Machine-readable output");
  return [o] { return devices(*o); };
}

}  // namespace erodem::cli
