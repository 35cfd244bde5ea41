// erodem tests — closed-form reference solutions and the error measures the analytical tests
// apply to them: dam breaks (Stoker, Ritter), steady sediment adaptation along a uniform flow,
// evaporation. Pure functions of doubles (no simulation), so a validation report can reuse
// them with the scenario set-ups of scenarios.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

namespace erodem::test {

constexpr double kG = 9.81;  ///< gravity (m/s^2), Params::flow.gravity's default

/// Stoker's (1957) wet-bed dam break on a flat frictionless bed: depth h0 upstream of the dam
/// (x < 0), h1 downstream (m). A rarefaction runs upstream from x = -c0 t, a middle state
/// (h2, u2) follows, and a shock runs downstream at `shock` (m/s).
struct Stoker {
  double h0, h1, h2 = 0, u2 = 0, shock = 0;
  Stoker(double up, double down) : h0(up), h1(down) {
    // Middle state: rarefaction u2 = 2 (c0 - c2) equals the shock's u2 = S (1 - h1 / h2),
    // S = sqrt(g h2 (h1 + h2) / (2 h1)); bisection on h2 in (h1, h0).
    const double c0 = std::sqrt(kG * h0);
    auto mismatch = [&](double h) {
      const double s = std::sqrt(kG * h * (h1 + h) / (2 * h1));
      return 2 * (c0 - std::sqrt(kG * h)) - s * (1 - h1 / h);
    };
    double lo = h1, hi = h0;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (mismatch(mid) > 0 ? lo : hi) = mid;
    }
    h2 = 0.5 * (lo + hi);
    u2 = 2 * (c0 - std::sqrt(kG * h2));
    shock = std::sqrt(kG * h2 * (h1 + h2) / (2 * h1));
  }
  double c0() const { return std::sqrt(kG * h0); }
  /// Where the rarefaction's head is at time t (s): x = -c0 t (m).
  double head(double t) const { return -c0() * t; }
  /// Depth (m) at distance x from the dam (m) at time t > 0 (s).
  double depth(double x, double t) const {
    const double c2 = std::sqrt(kG * h2);
    if (x <= -c0() * t) return h0;
    if (x <= (u2 - c2) * t) return std::pow(2 * c0() - x / t, 2) / (9 * kG);
    if (x <= shock * t) return h2;
    return h1;
  }
  /// Depth-averaged velocity (m/s): 0 upstream, (2/3)(c0 + x/t) in the fan, u2 in the middle
  /// state, 0 downstream of the shock.
  double velocity(double x, double t) const {
    const double c2 = std::sqrt(kG * h2);
    if (x <= -c0() * t) return 0;
    if (x <= (u2 - c2) * t) return 2.0 / 3.0 * (c0() + x / t);
    if (x <= shock * t) return u2;
    return 0;
  }
};

/// Ritter's (1892) dam break onto a dry flat frictionless bed: depth h0 upstream (m). The fan
/// runs from x = -c0 t to the wet front at x = 2 c0 t, with h = (2 c0 - x/t)^2 / (9 g) and
/// u = (2/3)(c0 + x/t).
struct Ritter {
  double h0;
  double c0() const { return std::sqrt(kG * h0); }
  double head(double t) const { return -c0() * t; }
  double front(double t) const { return 2 * c0() * t; }
  /// Where the exact depth falls to `threshold` (m): (2 c0 - x/t)^2 / (9 g) = threshold.
  double front_at(double threshold, double t) const {
    return (2 * c0() - 3 * std::sqrt(kG * threshold)) * t;
  }
  double depth(double x, double t) const {
    if (x <= -c0() * t) return h0;
    if (x >= 2 * c0() * t) return 0;
    return std::pow(2 * c0() - x / t, 2) / (9 * kG);
  }
  double velocity(double x, double t) const {
    if (x <= -c0() * t || x >= 2 * c0() * t) return 0;
    return 2.0 / 3.0 * (c0() + x / t);
  }
};

/// Steady suspended sediment (m) at distance x (m) downstream of a clear inflow into a uniform
/// flow of speed u (m/s) that erodes at rate K_s (1/s) towards the capacity C (m):
/// u ds/dx = K_s (C - s), s(0) = 0, so s = C (1 - exp(-K_s x / u)).
inline double adapted_sediment(double capacity, double dissolving_rate, double speed, double x) {
  return capacity * (1 - std::exp(-dissolving_rate * x / speed));
}

/// Depth (m) after n steps of evaporation with the clamped explicit rule d <- d (1 - K_e dt):
/// d0 (1 - min(1, K_e dt))^n. (Not d0 exp(-K_e n dt): the scheme is the explicit step.)
inline double evaporated_depth(double d0, double rate, double dt, long n) {
  return d0 * std::pow(1 - std::min(1.0, rate * dt), static_cast<double>(n));
}

/// Rain of intensity `rain` (m/s) from t = 0 on a dry plane of length `length` (m), slope
/// `slope` (1, the sine's tangent) and Manning n `manning` (s m^-1/3): the kinematic-wave
/// discharge per unit width at its foot (Eagleson 1970; Singh 1996): h = i t and
/// q = alpha h^(5/3), alpha = sqrt(S) / n, until the characteristic from the top arrives at
/// t_e = (L / (alpha i^(2/3)))^(3/5); from then on q = i L.
struct KinematicPlane {
  double length, slope, manning, rain;
  double alpha() const { return std::sqrt(slope) / manning; }
  double t_equilibrium() const {
    return std::pow(length / (alpha() * std::pow(rain, 2.0 / 3.0)), 0.6);
  }
  /// Discharge per unit width (m^2/s) leaving the foot at time t (s).
  double outlet(double t) const {
    const double te = t_equilibrium();
    return t < te ? alpha() * std::pow(rain * t, 5.0 / 3.0) : rain * length;
  }
  /// Volume per unit width (m^2) that left the foot between t = 0 and t (s).
  double outlet_volume(double t) const {
    const double te = t_equilibrium();
    const double rising = 0.375 * alpha() * std::pow(rain, 5.0 / 3.0);  // 3/8 alpha i^(5/3)
    return t < te ? rising * std::pow(t, 8.0 / 3.0)
                  : rising * std::pow(te, 8.0 / 3.0) + rain * length * (t - te);
  }
};

// ---- profiles on a 1-D row of cells ----------------------------------------------------

/// A 1-D profile sampled at the centres of `n` cells of `dx` m, the first one's west face at
/// `x_first` m: centre(c) = x_first + (c + 0.5) dx.
struct Row {
  int n;
  double dx, x_first;
  double centre(int c) const { return x_first + (c + 0.5) * dx; }
  std::vector<double> sample(const std::function<double(double)>& f) const {
    std::vector<double> v(static_cast<std::size_t>(n));
    for (int c = 0; c < n; ++c) v[static_cast<std::size_t>(c)] = f(centre(c));
    return v;
  }
};

/// The largest |v| (0 for an empty vector).
inline double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

/// Sum over the cells whose centres lie in [lo, hi] (m) of |a - b| (the L1 distance).
inline double l1_in(const Row& row, const std::vector<double>& a, const std::vector<double>& b,
                    double lo, double hi) {
  double s = 0;
  for (int c = 0; c < row.n; ++c) {
    const double x = row.centre(c);
    if (x >= lo && x <= hi)
      s += std::abs(a[static_cast<std::size_t>(c)] - b[static_cast<std::size_t>(c)]);
  }
  return s;
}

/// The relative L1 error of `numerical` against `exact` over [lo, hi]: the distance divided by
/// that of `idle` (the state before anything happened) from `exact`. A solver that did nothing
/// scores exactly 1; the exact solution 0.
inline double relative_l1(const Row& row, const std::vector<double>& numerical,
                          const std::vector<double>& exact, const std::vector<double>& idle,
                          double lo, double hi) {
  return l1_in(row, numerical, exact, lo, hi) / l1_in(row, idle, exact, lo, hi);
}

/// The centre (m) of the last cell whose value exceeds `threshold` (a front found by a
/// threshold, the same way on a numerical and an exact profile); the first centre if none.
inline double last_above(const Row& row, const std::vector<double>& v, double threshold) {
  int last = 0;
  for (int c = 0; c < row.n; ++c)
    if (v[static_cast<std::size_t>(c)] > threshold) last = c;
  return row.centre(last);
}

/// Averages of `fine` over consecutive blocks of `factor` cells (a fine profile restricted to
/// a grid `factor` times coarser whose faces coincide with fine faces).
inline std::vector<double> restrict_mean(const std::vector<double>& fine, int factor) {
  std::vector<double> coarse(fine.size() / static_cast<std::size_t>(factor), 0.0);
  for (std::size_t c = 0; c < coarse.size(); ++c) {
    for (int k = 0; k < factor; ++k) coarse[c] += fine[c * factor + static_cast<std::size_t>(k)];
    coarse[c] /= factor;
  }
  return coarse;
}

/// The observed order of convergence from two errors at resolutions `ratio` apart:
/// log(e_coarse / e_fine) / log(ratio).
inline double observed_order(double e_coarse, double e_fine, double ratio = 2.0) {
  return std::log(e_coarse / e_fine) / std::log(ratio);
}

}  // namespace erodem::test
