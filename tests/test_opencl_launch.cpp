// erodem — how the OpenCL backend covers a padded row with work-groups on CPU devices
// (whole_row_launch, kernels/opencl/runtime.cpp): every width gets whole-row launches, groups
// of at least min(32, W) work-items and at most the limit, then a tail group; no device needed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>

#ifdef ERODEM_HAVE_OPENCL
#include "opencl/opencl_backend.hpp"

namespace {

using erodem::opencl::RowLaunch;
using erodem::opencl::whole_row_launch;

// Against a brute force over the allowed sizes for every width 3 .. 20000 and three limits:
// the group leaves the shortest tail, the largest group among equals; where W has a divisor in
// [32, limit] (or W <= limit) the tail is 0 and the group that divisor, the largest: the
// launches of every such width are those from before the tails (2026-11-29). And the widths
// the docs name (performance.md "Whole-row launches for any width").
TEST(OpenClLaunch, WholeRowLaunchCoversEveryRowWidth) {
  int widths = 0, tails = 0, differ = 0;
  std::size_t longest = 0;
  for (const std::size_t limit : {std::size_t{1024}, std::size_t{256}, std::size_t{4096}})
    for (std::size_t W = 3; W <= 20000; ++W) {
      const RowLaunch got = whole_row_launch(W, limit);
      const std::size_t cap = std::min<std::size_t>(limit, 1024);
      const std::size_t hi = std::min(W, cap), lo = std::min<std::size_t>(32, hi);
      RowLaunch want{hi, W % hi};
      for (std::size_t g = hi; g >= lo; --g)
        if (W % g < want.tail) want = {g, W % g};
      std::size_t divisor = 0;  // the largest divisor in [lo, hi]
      for (std::size_t g = hi; g >= lo && divisor == 0; --g)
        if (W % g == 0) divisor = g;
      const bool ok = got.group == want.group && got.tail == want.tail && got.group >= lo &&
                      got.group <= hi && got.tail < got.group &&
                      (divisor == 0 || (got.tail == 0 && got.group == divisor));
      differ += !ok;
      ++widths;
      tails += got.tail > 0;
      longest = std::max(longest, got.tail);
      if (!ok)
        ADD_FAILURE() << "W " << W << " limit " << limit << ": group " << got.group << " tail "
                      << got.tail << " (expected " << want.group << " and " << want.tail << ")";
    }
  std::printf(
      "[opencl launch] %d widths and limits: %d with a tail, the longest tail %zu cells; %d "
      "differ from the brute force (bound 0)\n",
      widths, tails, longest, differ);
  EXPECT_EQ(differ, 0);
  const struct {
    std::size_t W, group, tail;
  } named[] = {{1229, 614, 1}, {1232, 616, 0}, {12290, 1024, 2}, {16387, 565, 2}, {2063, 687, 2},
               {5639, 805, 4}, {1031, 515, 1}, {4098, 683, 0},   {34, 34, 0},     {16, 16, 0}};
  for (const auto& n : named) {
    const RowLaunch got = whole_row_launch(n.W, 1024);
    EXPECT_EQ(got.group, n.group) << "W " << n.W;
    EXPECT_EQ(got.tail, n.tail) << "W " << n.W;
  }
}

}  // namespace
#endif
