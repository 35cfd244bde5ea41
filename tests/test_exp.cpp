// erodem — the float32 exp(-x) and relaxation weight (1 - exp(-x)) / x shared by the CPU
// reference and the OpenCL kernels (kernels/common/compat.h, used by the physical erosion law's
// exact exchange), and the float64 ones of the CPU reference: their error against a wider type
// over their range, in ulps of the float (double) nearest the exact value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/compat.h"

namespace erodem::test {
namespace {

/// |y - exact| in ulps of the Real nearest the exact value (computed in the wider type Wide).
template <class Real, class Wide>
double ulps(Wide exact, Real y) {
  const Real nearest = static_cast<Real>(exact);
  const Real ulp = std::nextafter(nearest, std::numeric_limits<Real>::infinity()) - nearest;
  return static_cast<double>(std::fabs(static_cast<Wide>(y) - exact) / static_cast<Wide>(ulp));
}

/// The largest errors of e^-x and (1 - e^-x)/x over x from `lo` to `hi`, each x a factor
/// (1 + 1/growth) above the last, against `exp_wide` and `expm1_wide` in the wider type.
struct Worst {
  double exp = 0, weight = 0, at_exp = 0, at_weight = 0;
  long values = 0;
};
template <class Real, class Wide>
Worst worst_errors(Real lo, Real hi, Real growth, Real (*exp_neg)(Real), Real (*weight)(Real),
                   Wide (*exp_wide)(Wide), Wide (*expm1_wide)(Wide)) {
  Worst w;
  for (Real x = lo; x < hi; x = std::nextafter(x * (1 + 1 / growth), hi + hi)) {
    const Wide wx = x;
    const double e = ulps(exp_wide(-wx), exp_neg(x));
    const double r = ulps(-expm1_wide(-wx) / wx, weight(x));
    if (e > w.exp) w.exp = e, w.at_exp = static_cast<double>(x);
    if (r > w.weight) w.weight = r, w.at_weight = static_cast<double>(x);
    ++w.values;
  }
  return w;
}

/// Prints the worst errors after `label` (with %ld for the count) and checks the bound, 2 ulps.
void expect_within_two_ulps(const char* label, const Worst& w) {
  std::printf(label, w.values);
  std::printf(": exp(-x) within %.2f ulp (at %g), weight within %.2f ulp (at %g); bound 2\n", w.exp,
              w.at_exp, w.weight, w.at_weight);
  EXPECT_LT(w.exp, 2.0);
  EXPECT_LT(w.weight, 2.0);
}

TEST(ExpNeg, WithinTwoUlpsFromZeroToTheSmallestNormal) {
  // Floats from 1e-8 to 87 in steps of about 2^-14 relative (374 thousand values), plus the
  // ends: 1 at x = 0 exactly, 0 beyond 87 (exp(-87) = 1.6e-38, just above the smallest
  // normal float 1.2e-38). Bound 2 ulps: the Taylor tail (6e-9) plus a handful of roundings;
  // a wrong coefficient or reduction costs thousands.
  const Worst w = worst_errors<float, double>(1e-8f, 87.0f, 16384.0f, cell::exp_neg_f32,
                                              cell::relax_weight_f32, std::exp, std::expm1);
  expect_within_two_ulps("[exp] %ld values in [1e-8, 87)", w);
  EXPECT_EQ(cell::exp_neg_f32(0.0f), 1.0f);
  EXPECT_EQ(cell::relax_weight_f32(0.0f), 1.0f);
  EXPECT_EQ(cell::exp_neg_f32(88.0f), 0.0f);
  EXPECT_EQ(cell::exp_neg_f32(std::numeric_limits<float>::infinity()), 0.0f);
}

TEST(ExpNeg, Float64WithinTwoUlpsFromZeroToTheSmallestNormal) {
  // The CPU float64 reference's exp(-x) and weight: doubles from 1e-12 to 708 in steps of
  // about 2^-16 relative (2.2 million values), against long double's expl and expm1l, plus the
  // ends (1 at 0, 0 beyond 708). Bound 2 ulps, as for float; a wrong coefficient, the float
  // version or a reduction in one part of ln 2 cost thousands (the Taylor tails: 5e-18, 2e-18).
  const Worst w = worst_errors<double, long double>(1e-12, 708.0, 65536.0, cell::exp_neg_f64,
                                                    cell::relax_weight_f64, expl, expm1l);
  expect_within_two_ulps("[exp f64] %ld values in [1e-12, 708)", w);
  EXPECT_EQ(cell::exp_neg_f64(0.0), 1.0);
  EXPECT_EQ(cell::relax_weight_f64(0.0), 1.0);
  EXPECT_EQ(cell::exp_neg_f64(709.0), 0.0);
  EXPECT_EQ(cell::exp_neg_f64(std::numeric_limits<double>::infinity()), 0.0);
}

}  // namespace
}  // namespace erodem::test
