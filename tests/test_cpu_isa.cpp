// erodem — the CPU kernels built for each x86-64 level (kernels/cpu/dispatch.cpp; chosen by
// ERODEM_CPU_ISA) give the same bits: a full erosion run on a crop of a real DEM on every
// level this CPU supports, every field and the ledger compared byte for byte with the
// x86-64-v2 baseline (bound: 0 differing values).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/simulation.hpp"
#include "scenarios.hpp"

namespace erodem::test {
namespace {

/// Sets ERODEM_CPU_ISA for its lifetime and restores the previous value (or its absence).
class ScopedCpuIsa {
 public:
  explicit ScopedCpuIsa(const std::string& isa) {
    if (const char* old = std::getenv("ERODEM_CPU_ISA")) old_ = old;
    setenv("ERODEM_CPU_ISA", isa.c_str(), 1);
  }
  ~ScopedCpuIsa() {
    if (old_)
      setenv("ERODEM_CPU_ISA", old_->c_str(), 1);
    else
      unsetenv("ERODEM_CPU_ISA");
  }
  ScopedCpuIsa(const ScopedCpuIsa&) = delete;
  ScopedCpuIsa& operator=(const ScopedCpuIsa&) = delete;

 private:
  std::optional<std::string> old_;
};

struct IsaCase {
  std::string name;
  FlowScheme flow;
  TransportScheme transport;
  bool adaptive;
  double dt;  ///< s: the fixed step, or the upper bound of the adaptive one
  Precision precision;
};

/// The storm of tests/test_agreement.cpp on the 256 x 256 Big Tujunga crop: rain, flow,
/// erosion, transport, thermal erosion and evaporation all active.
Params isa_params(const IsaCase& c) {
  return tujunga_storm(c.flow, c.transport, c.adaptive, c.dt, c.precision);
}

/// The case of the tests of the choice itself (no steps are run).
const IsaCase kChoiceCase{"choice", FlowScheme::local_inertial, TransportScheme::conservative, true,
                          2.0,      Precision::float32};

constexpr int kSteps = 200;

/// What a run leaves: every field, the model time and the ledger's totals.
struct RunResult {
  std::string device;
  std::vector<std::vector<double>> fields;
  std::vector<double> scalars;  ///< time, water, material, rain, boundary out
};

/// Every field; kFields[11] is the erosion.
const std::array<FieldId, 14> kFields = {
    FieldId::bed,         FieldId::water_depth, FieldId::sediment,   FieldId::velocity_x,
    FieldId::velocity_y,  FieldId::flux_left,   FieldId::flux_right, FieldId::flux_top,
    FieldId::flux_bottom, FieldId::hardness,    FieldId::wetness,    FieldId::erosion,
    FieldId::manning_n,   FieldId::initial_bed};

/// Whether this binary holds the CPU build `isa` and the CPU supports it. The builds a binary
/// lacks (ERODEM_NATIVE, another processor or compiler: only one) and the levels the CPU
/// lacks are skipped; any other error fails the test.
std::unique_ptr<Backend> backend_on(const std::string& isa, const Terrain& terrain,
                                    const Params& params) {
  ScopedCpuIsa scoped(isa);
  try {
    return make_backend("cpu", terrain, params);
  } catch (const Error& e) {
    const std::string what = e.what();
    const bool absent = what.find("this CPU does not support") != std::string::npos ||
                        what.find("no such CPU kernel build") != std::string::npos;
    EXPECT_TRUE(absent) << what;
    EXPECT_EQ(e.code(), ExitCode::usage) << what;
    std::printf("[cpu isa] %s: skipped: %s\n", isa.c_str(), e.what());
    return nullptr;
  }
}

/// Runs kSteps steps on the CPU build `isa`; nullopt when it cannot run here.
std::optional<RunResult> run_on(const std::string& isa, const Terrain& terrain,
                                const Params& params) {
  std::unique_ptr<Backend> backend = backend_on(isa, terrain, params);
  if (!backend) return std::nullopt;
  Simulation sim(terrain, params, std::move(backend));
  sim.step(kSteps);
  RunResult r;
  r.device = sim.backend().device();
  for (FieldId id : kFields) r.fields.push_back(sim.field(id));
  const auto& L = sim.ledger();
  r.scalars = {sim.time(), L.water, L.material, L.rain, L.boundary_out};
  return r;
}

/// Values of `a` whose bytes differ from `b`'s.
std::size_t differing(const std::vector<double>& a, const std::vector<double>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0) ++n;
  return n;
}

class CpuIsa : public ::testing::TestWithParam<IsaCase> {};

TEST_P(CpuIsa, EveryLevelGivesTheBaselineBits) {
  const IsaCase& c = GetParam();
  const Params params = isa_params(c);
  const Terrain terrain = io::read_dem(params.dem);
  const auto base = run_on("v2", terrain, params);
  if (!base) GTEST_SKIP() << "no x86-64-v2 build: this binary has one CPU build";
  // The run must exercise the kernels: water everywhere, and erosion or deposition.
  const auto& erosion = base->fields[11];
  std::size_t eroded = 0;
  for (double e : erosion) eroded += e != 0.0;
  std::printf("[cpu isa] %s: %zu of %zu cells eroded or filled after %d steps (bound > 0)\n",
              c.name.c_str(), eroded, erosion.size(), kSteps);
  EXPECT_GT(eroded, 0u);
  EXPECT_NE(base->device.find("SSE4.2"), std::string::npos) << base->device;
  int compared = 0;
  for (const std::string isa : {"v3", "v4"}) {
    const auto other = run_on(isa, terrain, params);
    if (!other) continue;
    ++compared;
    EXPECT_NE(other->device.find(isa == "v3" ? "AVX2" : "AVX-512"), std::string::npos)
        << other->device;
    std::size_t total = 0;
    for (std::size_t f = 0; f < kFields.size(); ++f) {
      ASSERT_EQ(other->fields[f].size(), base->fields[f].size());
      const std::size_t n = differing(other->fields[f], base->fields[f]);
      std::printf("[cpu isa] %s %s vs v2: %-12s %zu of %zu values differ (bound 0)\n",
                  c.name.c_str(), isa.c_str(), field_info(kFields[f]).name, n,
                  base->fields[f].size());
      EXPECT_EQ(n, 0u) << isa << " " << field_info(kFields[f]).name;
      total += n;
    }
    const std::size_t ns = differing(other->scalars, base->scalars);
    std::printf(
        "[cpu isa] %s %s ('%s') vs v2 ('%s') after %d steps: time %.9g s, water %.9g m^3; "
        "%zu of %zu ledger values differ (bound 0); %zu field values differ in all (bound 0)\n",
        c.name.c_str(), isa.c_str(), other->device.c_str(), base->device.c_str(), kSteps,
        other->scalars[0], other->scalars[1], ns, base->scalars.size(), total);
    EXPECT_EQ(ns, 0u) << isa;
  }
  if (compared == 0) GTEST_SKIP() << "this CPU supports only x86-64-v2 (or no other build)";
}

// The reductions sum per row and then the rows in order (cpu_backend.hpp), so the number of
// OpenMP threads changes nothing: 1, 2 and 3 threads (3 splits the 256 rows unevenly) give
// the same bits on the default build. A reduction summed per thread, or a race between rows
// that read their neighbours, would differ (bound: 0 differing values).
TEST_P(CpuIsa, EveryThreadCountGivesTheSameBits) {
  const IsaCase& c = GetParam();
  Params params = isa_params(c);
  const Terrain terrain = io::read_dem(params.dem);
  auto run_with = [&](int threads) {
    params.numerics.threads = threads;
    Simulation sim(terrain, params, make_backend("cpu", terrain, params));
    sim.step(kSteps);
    RunResult r;
    r.device = sim.backend().device();
    for (FieldId id : kFields) r.fields.push_back(sim.field(id));
    const auto& L = sim.ledger();
    r.scalars = {sim.time(), L.water, L.material, L.rain, L.boundary_out, L.eroded, L.deposited};
    return r;
  };
  const RunResult one = run_with(1);
  for (int threads : {2, 3}) {
    const RunResult other = run_with(threads);
    std::size_t total = 0;
    for (std::size_t f = 0; f < kFields.size(); ++f)
      total += differing(other.fields[f], one.fields[f]);
    const std::size_t ns = differing(other.scalars, one.scalars);
    std::printf(
        "[cpu threads] %s: '%s' vs '%s' after %d steps: %zu field values and %zu of %zu ledger "
        "values differ (bound 0)\n",
        c.name.c_str(), other.device.c_str(), one.device.c_str(), kSteps, total, ns,
        one.scalars.size());
    EXPECT_EQ(total, 0u) << threads << " threads";
    EXPECT_EQ(ns, 0u) << threads << " threads";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Tujunga, CpuIsa,
    ::testing::Values(IsaCase{"local_inertial_conservative_f32", FlowScheme::local_inertial,
                              TransportScheme::conservative, true, 2.0, Precision::float32},
                      IsaCase{"pipes_semi_lagrangian_f32", FlowScheme::pipes,
                              TransportScheme::semi_lagrangian, false, 0.5, Precision::float32},
                      IsaCase{"local_inertial_conservative_f64", FlowScheme::local_inertial,
                              TransportScheme::conservative, true, 2.0, Precision::float64}),
    [](const ::testing::TestParamInfo<IsaCase>& i) { return i.param.name; });

TEST(CpuIsaChoice, UnknownLevelIsAUsageError) {
  const Params params = isa_params(kChoiceCase);
  const Terrain terrain = io::read_dem(params.dem);
  ScopedCpuIsa scoped("v9");
  try {
    make_backend("cpu", terrain, params);
    FAIL() << "ERODEM_CPU_ISA=v9 was accepted";
  } catch (const Error& e) {
    std::printf("[cpu isa] ERODEM_CPU_ISA=v9: exit code %d, '%s'\n", static_cast<int>(e.code()),
                e.what());
    EXPECT_EQ(e.code(), ExitCode::usage);
    EXPECT_NE(std::string(e.what()).find("ERODEM_CPU_ISA=v9"), std::string::npos);
  }
}

TEST(CpuIsaChoice, DefaultIsTheBestSupportedLevel) {
  const Params params = isa_params(kChoiceCase);
  const Terrain terrain = io::read_dem(params.dem);
  if (!backend_on("v2", terrain, params))
    GTEST_SKIP() << "no x86-64-v2 build: this binary has one CPU build";
  std::string best = "v2";
  for (const std::string isa : {"v3", "v4"})
    if (backend_on(isa, terrain, params)) best = isa;
  ScopedCpuIsa scoped("");
  const std::string device = make_backend("cpu", terrain, params)->device();
  const char* label = best == "v4" ? "AVX-512" : best == "v3" ? "AVX2" : "SSE4.2";
  std::printf("[cpu isa] default: '%s' (best supported level: %s)\n", device.c_str(), best.c_str());
  EXPECT_NE(device.find(label), std::string::npos) << device;
}

}  // namespace
}  // namespace erodem::test
