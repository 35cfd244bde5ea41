// erodem — a GoogleTest environment that releases the OpenCL runtimes (contexts, queues,
// programs) before the test program's `main` returns, as the CLI and the Python module do:
// never from a static destructor, when the OpenCL implementation may already be tearing
// itself down (backends.hpp, release_opencl_runtimes). It also checks that every test let
// its backends go: a runtime still held by a live backend after the last test is a leak
// (a backend kept in a static, or one a test forgot), and fails the program.
#include <gtest/gtest.h>

#include "erodem/backends.hpp"

namespace {

class ReleaseOpenClRuntimes : public ::testing::Environment {
 public:
  void TearDown() override {
    const std::size_t still_held = erodem::release_opencl_runtimes();
    EXPECT_EQ(still_held, 0u) << "OpenCL runtimes still held by live backends after the last "
                                 "test (a backend outlived its test)";
  }
};

// Registered during static initialisation, before gtest_main's RUN_ALL_TESTS; GoogleTest
// owns and deletes the environment.
[[maybe_unused]] ::testing::Environment* const release_environment =
    ::testing::AddGlobalTestEnvironment(new ReleaseOpenClRuntimes);

}  // namespace
