// erodem — the float32 exp(-x) and relaxation weight (1 - exp(-x)) / x shared by the CPU
// reference and the OpenCL kernels (kernels/common/compat.h, used by the physical erosion law's
// exact exchange): their error against double over their range, in ulps of the float nearest
// the exact value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/compat.h"

namespace erodem::test {
namespace {

double ulps(double exact, float y) {
  const float nearest = static_cast<float>(exact);
  const double ulp = std::nextafter(nearest, std::numeric_limits<float>::infinity()) - nearest;
  return std::fabs(static_cast<double>(y) - exact) / ulp;
}

TEST(ExpNeg, WithinTwoUlpsFromZeroToTheSmallestNormal) {
  // Floats from 1e-8 to 87 in steps of about 2^-14 relative (374 thousand values), plus the
  // ends: 1 at x = 0 exactly, 0 beyond 87 (exp(-87) = 1.6e-38, just above the smallest
  // normal float 1.2e-38). Bound 2 ulps: the Taylor tail (6e-9) plus a handful of roundings;
  // a wrong coefficient or reduction costs thousands.
  double worst_exp = 0, worst_weight = 0, at_exp = 0, at_weight = 0;
  long n = 0;
  for (float x = 1e-8f; x < 87.0f; x = std::nextafter(x * (1.0f + 1.0f / 16384.0f), 100.0f)) {
    const double e = ulps(std::exp(-static_cast<double>(x)), cell::exp_neg_f32(x));
    const double w = ulps(-std::expm1(-static_cast<double>(x)) / static_cast<double>(x),
                          cell::relax_weight_f32(x));
    if (e > worst_exp) worst_exp = e, at_exp = x;
    if (w > worst_weight) worst_weight = w, at_weight = x;
    ++n;
  }
  std::printf(
      "[exp] %ld values in [1e-8, 87): exp(-x) within %.2f ulp (at %g), weight within "
      "%.2f ulp (at %g); bound 2\n",
      n, worst_exp, at_exp, worst_weight, at_weight);
  EXPECT_LT(worst_exp, 2.0);
  EXPECT_LT(worst_weight, 2.0);
  EXPECT_EQ(cell::exp_neg_f32(0.0f), 1.0f);
  EXPECT_EQ(cell::relax_weight_f32(0.0f), 1.0f);
  EXPECT_EQ(cell::exp_neg_f32(88.0f), 0.0f);
  EXPECT_EQ(cell::exp_neg_f32(std::numeric_limits<float>::infinity()), 0.0f);
}

}  // namespace
}  // namespace erodem::test
