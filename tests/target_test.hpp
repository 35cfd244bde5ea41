// erodem tests — the fixture and instantiation shared by the tests that run on every target
// (cpu_float32, cpu_float64 and, where the OpenCL backend is built, opencl_float32).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "erodem/backends.hpp"
#include "scenarios.hpp"
#include "validation_record.hpp"

namespace erodem::test {

/// Base of a test suite parameterised over targets: skips OpenCL targets where no OpenCL
/// device is found.
class TargetTest : public ::testing::TestWithParam<Target> {
 protected:
  const Target& target() const { return GetParam(); }
  void SetUp() override {
    if (target().backend == "opencl" && !opencl_available()) GTEST_SKIP() << "no OpenCL device";
  }
  /// Rounding-level bound: `f64` in float64, `f32` in float32.
  double bound(double f64, double f32) const { return target().f64() ? f64 : f32; }
  /// A figure of the validation report (validation_record.hpp) measured on this target.
  validation::Figure figure(const char* case_id, const std::string& scheme, const char* quantity,
                            double resolution, const char* reference) const {
    return {case_id, target().label(), scheme, quantity, resolution, reference};
  }
};

/// gtest's name of a target's instance: its label.
inline std::string target_name(const ::testing::TestParamInfo<Target>& info) {
  return info.param.label();
}

}  // namespace erodem::test

#ifdef ERODEM_HAVE_OPENCL
#define ERODEM_INSTANTIATE_OPENCL_TARGETS(suite)                                         \
  INSTANTIATE_TEST_SUITE_P(                                                              \
      OpenCl, suite,                                                                     \
      ::testing::Values(::erodem::test::Target{"opencl", ::erodem::Precision::float32}), \
      ::erodem::test::target_name)
#else
#define ERODEM_INSTANTIATE_OPENCL_TARGETS(suite) static_assert(true, "no OpenCL backend")
#endif

/// Instantiates `suite` (a TargetTest) as Cpu/<suite>.<test>/cpu_float32, .../cpu_float64 and,
/// with the OpenCL backend built, OpenCl/<suite>.<test>/opencl_float32.
#define ERODEM_INSTANTIATE_TARGETS(suite)                                             \
  INSTANTIATE_TEST_SUITE_P(                                                           \
      Cpu, suite,                                                                     \
      ::testing::Values(::erodem::test::Target{"cpu", ::erodem::Precision::float32},  \
                        ::erodem::test::Target{"cpu", ::erodem::Precision::float64}), \
      ::erodem::test::target_name);                                                   \
  ERODEM_INSTANTIATE_OPENCL_TARGETS(suite)
