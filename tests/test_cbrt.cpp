// erodem — the float32 cube root shared by the CPU reference and the OpenCL kernels, and the
// float64 one of the CPU reference (kernels/common/compat.h): their errors against the exact
// root over a sample of every binade of their range [1e-30, 1e38] (bound: 1 ulp), and the
// local-inertial face's floor that keeps the root in that range and the friction term finite
// (kernels/common/flow.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

#include "common/flow.h"

namespace erodem::test {
namespace {

std::uint32_t float_bits(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

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

TEST(Cbrt, WithinOneUlpOverEveryBinadeOfItsRange) {
  // Every 61st bit pattern from 1e-30 to 1e38: 25 million values, mantissas spread over
  // each binade, both ends included.
  const auto lo = float_bits(ERODEM_CBRT_MIN), hi = float_bits(ERODEM_CBRT_MAX);
  double worst = 0;
  float worst_x = 0;
  std::uint64_t count = 0;
  auto check = [&](std::uint32_t b) {
    const float x = float_from_bits(b);
    const double e = ulp_error(x, cell::cbrt_f32_positive(x));
    if (e > worst) worst = e, worst_x = x;
    ++count;
  };
  for (std::uint32_t b = lo; b < hi; b += 61) check(b);
  check(hi);
  std::printf(
      "cbrt_f32_positive: %llu values in [%g, %g], max error %.3f ulp at x = %.9g "
      "(bound 1 ulp)\n",
      static_cast<unsigned long long>(count), static_cast<double>(ERODEM_CBRT_MIN),
      static_cast<double>(ERODEM_CBRT_MAX), worst, static_cast<double>(worst_x));
  EXPECT_LE(worst, 1.0);
  EXPECT_TRUE(std::isnan(cell::cbrt_f32_positive(std::nanf(""))));
  EXPECT_EQ(cell::cbrt_f32_positive(27.0f), 3.0f);
  EXPECT_EQ(cell::cbrt_f32_positive(0.125f), 0.5f);
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

/// |y - cbrt(x)| in units of the last place of the double nearest the exact root (long
/// double's cbrtl as the exact root: 64-bit mantissa on x86-64, 11 bits beyond double's).
double ulp_error_f64(double x, double y) {
  const long double exact = cbrtl(static_cast<long double>(x));
  const double nearest = static_cast<double>(exact);
  const double ulp = std::nextafter(nearest, std::numeric_limits<double>::infinity()) - nearest;
  return static_cast<double>(std::fabs(static_cast<long double>(y) - exact) / ulp);
}

TEST(Cbrt, Float64WithinOneUlpOverEveryBinadeOfItsRange) {
  // cbrt_f64_positive (the CPU float64 reference's root, a float guess and one Halley step):
  // 2^22 spaced bit patterns of [1e-30, 1e38] and a million random mantissas near 1, where
  // the flow's depths are. Bound 1 ulp, as for the C library's cbrt it replaced; the float
  // guess alone is off by ~1e6 double ulps, a Halley step with a wrong sign by far more.
  std::uint64_t lo, hi;
  const double dlo = ERODEM_CBRT_MIN, dhi = ERODEM_CBRT_MAX;
  std::memcpy(&lo, &dlo, sizeof lo);
  std::memcpy(&hi, &dhi, sizeof hi);
  double worst = 0, worst_x = 0;
  std::uint64_t count = 0;
  auto check = [&](double x) {
    const double e = ulp_error_f64(x, cell::cbrt_f64_positive(x));
    if (e > worst) worst = e, worst_x = x;
    ++count;
  };
  const std::uint64_t stride = (hi - lo) >> 22;
  for (std::uint64_t b = lo; b < hi; b += stride) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    check(x);
  }
  check(dhi);
  std::uint64_t state = 88172645463325252ull;  // xorshift64: the same sample every run
  for (int k = 0; k < 1000000; ++k) {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    check(0.5 + static_cast<double>(state >> 11) * 0x1p-53 * 7.5);  // [0.5, 8)
  }
  std::printf(
      "cbrt_f64_positive: %llu values in [%g, %g], max error %.3f ulp at x = %.17g "
      "(bound 1 ulp)\n",
      static_cast<unsigned long long>(count), dlo, dhi, worst, worst_x);
  EXPECT_LE(worst, 1.0);
  EXPECT_TRUE(std::isnan(cell::cbrt_f64_positive(std::nan(""))));
  EXPECT_EQ(cell::cbrt_f64_positive(27.0), 3.0);
  EXPECT_EQ(cell::cbrt_f64_positive(0.125), 0.5);
}

// A face whose flow depth h_f is at or below ERODEM_FACE_DEPTH_MIN is dry even where
// dry_depth is smaller (0 or 1e-20 m), in float and in double (the CPU float64 reference);
// just above it, the friction term stays finite with q = 0 (before the floor, h_f = 1e-20 m
// gave h_f^(7/3) = 0 in float and q_new = NaN from 0 / 0).
template <class Real>
int check_face_depth_floor(Real dry_depth, Real* largest) {
  const Real g = 9.81, dt = 1, n = 0.03, dist = 10, theta = 0.7;
  auto q_new = [&](Real h, Real q) {  // a face over a flat bed at 0 with a surface drop
    return cell::local_inertial_q<Real>(q, q, q, h, Real(0.5) * h, 0, 0, n, dist, dt, g, theta,
                                        dry_depth);
  };
  const Real floor = ERODEM_FACE_DEPTH_MIN;
  int checked = 0;
  for (Real h : {Real(1e-30), Real(1e-20), Real(1e-17), floor}) {
    EXPECT_EQ(q_new(h, 0), Real(0)) << "h_f = " << h << ", dry_depth = " << dry_depth;
    EXPECT_EQ(q_new(h, Real(1e-3)), Real(0)) << "h_f = " << h << ", dry_depth = " << dry_depth;
    ++checked;
  }
  for (Real h = std::nextafter(floor, Real(1)); h < Real(1e3); h *= Real(3.7))
    for (Real q : {Real(0), Real(1e-30), Real(1e-3), Real(1), Real(-5)}) {
      const Real r = q_new(h, q);
      EXPECT_TRUE(std::isfinite(r)) << "h_f = " << h << ", q = " << q;
      *largest = std::fmax(*largest, std::fabs(r));
      ++checked;
    }
  return checked;
}

TEST(Cbrt, FaceDepthFloorKeepsTheFrictionTermFinite) {
  float largest_f = 0;
  double largest_d = 0;
  int checked = 0;
  for (float dry : {0.0f, 1e-20f}) checked += check_face_depth_floor<float>(dry, &largest_f);
  for (double dry : {0.0, 1e-20}) checked += check_face_depth_floor<double>(dry, &largest_d);
  std::printf(
      "local_inertial_q with dry_depth = 0 and 1e-20 m, float and double: %d faces, dry at or "
      "below %g m, finite above (largest |q_new| %.4g / %.4g m^2/s)\n",
      checked, static_cast<double>(ERODEM_FACE_DEPTH_MIN), static_cast<double>(largest_f),
      largest_d);
}

}  // namespace
}  // namespace erodem::test
