// erodem — run-time choice of the CPU kernels' instruction set. kernels/CMakeLists.txt
// builds the CPU backend once per x86-64 level (namespaces erodem::cpu_v2, cpu_v3, cpu_v4;
// cpu/isa_prelude.hpp); this file, built once for the baseline, picks the best level the
// running CPU supports, or the one named by the environment variable ERODEM_CPU_ISA. All
// levels give bit-identical results (tests/test_cpu_isa.cpp); only the speed differs.
#include <fmt/format.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"

namespace erodem {

// The factories of the builds (cpu/cpu_backend.cpp, one per namespace). The level-2 build
// is always there (with ERODEM_NATIVE it is the -march=native build).
namespace cpu_v2 {
std::unique_ptr<Backend> make_cpu_backend_isa(const Terrain& terrain, const Params& params);
}
#ifdef ERODEM_CPU_HAVE_V3
namespace cpu_v3 {
std::unique_ptr<Backend> make_cpu_backend_isa(const Terrain& terrain, const Params& params);
}
#endif
#ifdef ERODEM_CPU_HAVE_V4
namespace cpu_v4 {
std::unique_ptr<Backend> make_cpu_backend_isa(const Terrain& terrain, const Params& params);
}
#endif

namespace {

using CpuFactory = std::unique_ptr<Backend> (*)(const Terrain&, const Params&);

/// One build of the CPU kernels.
struct CpuIsa {
  const char* name;         ///< value of ERODEM_CPU_ISA that selects it
  const char* description;  ///< for messages
  bool supported;           ///< whether this CPU (and OS) can run it
  CpuFactory make;
};

#if defined(ERODEM_CPU_HAVE_V3) || defined(ERODEM_CPU_HAVE_V4)
/// Whether the running CPU supports x86-64 level `level` (3 or 4), OS state saving included.
bool cpu_supports_level(int level) {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
  if (level == 3) return __builtin_cpu_supports("x86-64-v3");
  if (level == 4) return __builtin_cpu_supports("x86-64-v4");
#else
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                  __builtin_cpu_supports("f16c") && __builtin_cpu_supports("movbe");
  if (level == 3) return v3;
  if (level == 4)
    return v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512cd");
#endif
#endif
  (void)level;
  return false;
}
#endif

/// The builds in this binary, lowest level first.
std::vector<CpuIsa> cpu_isas() {
  std::vector<CpuIsa> isas;
#ifdef ERODEM_CPU_NATIVE
  isas.push_back({"native", "-march=native (ERODEM_NATIVE)", true, &cpu_v2::make_cpu_backend_isa});
#else
  isas.push_back({"v2", "x86-64-v2 (SSE4.2)", true, &cpu_v2::make_cpu_backend_isa});
#endif
#ifdef ERODEM_CPU_HAVE_V3
  isas.push_back({"v3", "x86-64-v3 (AVX2)", cpu_supports_level(3), &cpu_v3::make_cpu_backend_isa});
#endif
#ifdef ERODEM_CPU_HAVE_V4
  isas.push_back(
      {"v4", "x86-64-v4 (AVX-512)", cpu_supports_level(4), &cpu_v4::make_cpu_backend_isa});
#endif
  return isas;
}

/// The build to run: ERODEM_CPU_ISA's if set (an unknown or unsupported one is a usage
/// error, exit code 2, so a benchmark never measures another build than it names), else
/// the highest level this CPU supports.
const CpuIsa& choose_cpu_isa(const std::vector<CpuIsa>& isas) {
  const char* env = std::getenv("ERODEM_CPU_ISA");
  const std::string want = env ? env : "";
  std::string names, usable;
  for (const auto& isa : isas) {
    names += (names.empty() ? "" : ", ") + std::string(isa.name);
    if (isa.supported) usable += (usable.empty() ? "" : ", ") + std::string(isa.name);
  }
  if (want.empty() || want == "auto") {
    const CpuIsa* best = &isas.front();
    for (const auto& isa : isas)
      if (isa.supported) best = &isa;
    return *best;
  }
  for (const auto& isa : isas) {
    if (want != isa.name) continue;
    if (!isa.supported)
      throw Error(
          ExitCode::usage,
          fmt::format("ERODEM_CPU_ISA={}: this CPU does not support {}; expected one of: {}", want,
                      isa.description, usable));
    return isa;
  }
  throw Error(ExitCode::usage,
              fmt::format("ERODEM_CPU_ISA={}: no such CPU kernel build in this binary; expected "
                          "one of: {} (or unset/auto: the best this CPU supports)",
                          want, names));
}

}  // namespace

CpuIsaInfo cpu_isa_info() {
  const auto isas = cpu_isas();
  CpuIsaInfo info;
  for (const auto& isa : isas)
    info.built += (info.built.empty() ? "" : ", ") + std::string(isa.name);
  try {
    info.level = choose_cpu_isa(isas).description;
  } catch (const Error& e) {
    info.level = e.what();
  }
  return info;
}

std::unique_ptr<Backend> make_cpu_backend(const Terrain& terrain, const Params& params) {
  const auto isas = cpu_isas();
  return choose_cpu_isa(isas).make(terrain, params);
}

}  // namespace erodem
