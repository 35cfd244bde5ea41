// erodem — the float32 cube root shared by the CPU reference and the OpenCL kernels
// (kernels/common/compat.h): its error against the exact root, over a sample of every
// binade of positive floats, subnormals included (bound: 1 ulp), and its special cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

#include "common/compat.h"

namespace erodem::test {
namespace {

float float_from_bits(std::uint32_t b) {
  float x;
  std::memcpy(&x, &b, sizeof x);
  return x;
}

/// |y - cbrt(x)| in units of the last place of the float nearest the exact root.
double ulp_error(float x, float y) {
  const double exact = std::cbrt(static_cast<double>(x));
  const float nearest = static_cast<float>(exact);
  const double ulp = std::nextafter(nearest, std::numeric_limits<float>::infinity()) - nearest;
  return std::fabs(static_cast<double>(y) - exact) / ulp;
}

TEST(Cbrt, WithinOneUlpOverEveryBinade) {
  // Every 61st bit pattern from the smallest subnormal to the largest float: 35 million
  // values, all exponents, mantissas spread over each binade.
  double worst = 0;
  float worst_x = 0;
  std::uint64_t count = 0;
  for (std::uint64_t b = 1; b <= 0x7f7fffffu; b += 61) {
    const float x = float_from_bits(static_cast<std::uint32_t>(b));
    const double e = ulp_error(x, cell::cbrt_f32_positive(x));
    if (e > worst) worst = e, worst_x = x;
    ++count;
  }
  std::printf("cbrt_f32_positive: %llu values, max error %.3f ulp at x = %.9g (bound 1 ulp)\n",
              static_cast<unsigned long long>(count), worst, static_cast<double>(worst_x));
  EXPECT_LE(worst, 1.0);
}

TEST(Cbrt, FirstGuessWithinItsBound) {
  // The two Halley steps reach float rounding only from a guess within a few per cent.
  double worst = 0;
  for (std::uint64_t b = 0x00800000u; b <= 0x7f7fffffu; b += 4093) {
    const float x = float_from_bits(static_cast<std::uint32_t>(b));
    const double exact = std::cbrt(static_cast<double>(x));
    worst = std::fmax(worst, std::fabs(cell::cbrt_f32_guess(x) / exact - 1));
  }
  std::printf("cbrt_f32_guess: max relative error %.4f (bound 0.033)\n", worst);
  EXPECT_LE(worst, 0.033);
}

TEST(Cbrt, SpecialValuesAndSign) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(cell::cbrt_f32(0.0f), 0.0f);
  EXPECT_TRUE(std::signbit(cell::cbrt_f32(-0.0f)));
  EXPECT_EQ(cell::cbrt_f32(inf), inf);
  EXPECT_EQ(cell::cbrt_f32(-inf), -inf);
  EXPECT_TRUE(std::isnan(cell::cbrt_f32(std::nanf(""))));
  EXPECT_TRUE(std::isnan(cell::cbrt_f32_positive(std::nanf(""))));
  EXPECT_EQ(cell::cbrt_f32(27.0f), 3.0f);
  EXPECT_EQ(cell::cbrt_f32(-8.0f), -2.0f);
  EXPECT_EQ(cell::cbrt_f32(-5.0f), -cell::cbrt_f32(5.0f));
  std::printf("cbrt_f32(27) = %.9g, cbrt_f32(-8) = %.9g\n",
              static_cast<double>(cell::cbrt_f32(27.0f)),
              static_cast<double>(cell::cbrt_f32(-8.0f)));
}

}  // namespace
}  // namespace erodem::test
