// erodem — what every OpenCL C compiler accepts: the embedded kernel sources (kernels/common/*.h
// and kernels/opencl/*.cl, as the runtime builds them) use no construct that a conforming
// compiler may refuse though PoCL's and Oclgrind's clang accept it.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <sstream>
#include <string>

#ifdef ERODEM_HAVE_OPENCL
#include "opencl/embedded_sources.hpp"

namespace {

TEST(OpenClPortability, NoVariadicMacrosInTheKernelSources) {
  // NVIDIA's OpenCL compiler (driver 580, H200) refused the whole program on the first GPU run
  // (2026-11-27): "variadic macros not supported in OpenCL", at ERODEM_PARAMS(Name, ...) in
  // compat.h, and every kernel with it. PoCL (clang 15) and Oclgrind accept them, so nothing
  // else here would notice a new one: any #define whose parameters end in "..." fails.
  const std::regex variadic(R"(^\s*#\s*define\s+\w+\([^)]*\.\.\.\s*\))");
  int sources = 0, defines = 0;
  std::string found;
  for (std::size_t k = 0; k < erodem::opencl::kEmbeddedSourceCount; ++k) {
    const auto& src = erodem::opencl::kEmbeddedSources[k];
    ++sources;
    std::istringstream in(src.text);
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      if (line.find("define") != std::string::npos &&
          std::regex_search(line, std::regex(R"(^\s*#\s*define\s)")))
        ++defines;
      if (std::regex_search(line, variadic))
        found += std::string(src.name) + ":" + std::to_string(n) + ": " + line + "\n";
    }
  }
  std::printf("[opencl portability] %d sources, %d #defines, variadic: %s\n", sources, defines,
              found.empty() ? "none" : found.c_str());
  EXPECT_GT(sources, 20);  // every header and program, not an empty table
  EXPECT_GT(defines, 20);
  EXPECT_TRUE(found.empty()) << found;
}

}  // namespace
#endif
