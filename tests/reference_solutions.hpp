// erodem tests — closed-form reference solutions and the error measures the analytical tests
// apply to them: dam breaks (Stoker, Ritter), steady sediment adaptation along a uniform flow,
// evaporation; and a fine 1-D solver of the radially symmetric dam break, which has no closed
// form. Pure functions of doubles (no simulation), so a validation report can reuse them with
// the scenario set-ups of scenarios.hpp.
#pragma once

#include <algorithm>
#include <array>
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

/// The radially symmetric dam break on a flat frictionless bed: water `h_in` m deep within `r0`
/// m of the centre, `h_out` m (> 0) beyond. A shock runs outwards, weakening as it spreads, and a
/// rarefaction inwards, which reflects from the centre. No closed form: this solves the radially
/// symmetric shallow-water equations
///   h_t + (h u)_r = -h u / r,   (h u)_t + (h u^2 + g h^2 / 2)_r = -h u^2 / r
/// in their conservative form, multiplied by r,
///   (r h)_t + (r h u)_r = 0,    (r h u)_t + (r (h u^2 + g h^2 / 2))_r = g h^2 / 2,
/// by finite volumes on `n` annuli of dr = r_max / n (cell i: r in [i dr, (i + 1) dr], volume
/// r_i dr per radian, r_i its centre): HLL fluxes with Einfeldt's wave speeds through the faces
/// (of length r per radian: none at r = 0, which needs no other condition), the pressure source
/// g h_i^2 / 2 dr at the centre (so a lake at rest stays at rest exactly), MUSCL reconstruction
/// of h and u with the monotonised-central limiter and Heun's method (second order where the
/// solution is smooth), steps at Courant number 0.4, a wall at r_max. With `cylindrical` false
/// the same scheme solves the planar dam break (faces of length 1, no source): Stoker's
/// solution with the dam at r0, which checks the solver.
class RadialDamBreak {
 public:
  RadialDamBreak(double h_in, double h_out, double r0, double r_max, int n, bool cylindrical = true)
      : dr_(r_max / n),
        cylindrical_(cylindrical),
        h_(static_cast<std::size_t>(n)),
        q_(static_cast<std::size_t>(n), 0.0) {
    // cell averages of the initial step (the cell that holds r0: its area-weighted mean)
    for (int i = 0; i < n; ++i) {
      const double a = i * dr_, b = a + dr_;
      const double in = std::clamp(r0, a, b);
      h_[static_cast<std::size_t>(i)] =
          cylindrical ? (h_in * (in * in - a * a) + h_out * (b * b - in * in)) / (b * b - a * a)
                      : (h_in * (in - a) + h_out * (b - in)) / dr_;
    }
  }
  /// Advances the solution to time t (s; from the time reached so far).
  void run_to(double t) {
    while (t_ < t) {
      double speed = 0;
      for (std::size_t i = 0; i < h_.size(); ++i)
        speed = std::max(speed, std::abs(q_[i] / h_[i]) + std::sqrt(kG * h_[i]));
      const double dt = std::min(0.4 * dr_ / speed, t - t_);
      // Heun: U1 = U + dt L(U), U <- (U + U1 + dt L(U1)) / 2
      const std::vector<double> h0 = h_, q0 = q_;
      step(dt);
      step(dt);
      for (std::size_t i = 0; i < h_.size(); ++i) {
        h_[i] = 0.5 * (h0[i] + h_[i]);
        q_[i] = 0.5 * (q0[i] + q_[i]);
      }
      t_ += dt;
    }
  }
  double time() const { return t_; }
  /// Depth (m), discharge per unit width h u (m^2/s, outwards) and velocity (m/s) at radius r
  /// (m), linear between the cell centres.
  double depth(double r) const { return at(h_, r); }
  double discharge(double r) const { return at(q_, r); }
  double velocity(double r) const { return discharge(r) / depth(r); }
  /// The cells' averages.
  const std::vector<double>& depths() const { return h_; }
  double cell() const { return dr_; }

 private:
  double dr_, t_ = 0;
  bool cylindrical_;
  std::vector<double> h_, q_;

  double at(const std::vector<double>& v, double r) const {
    const double s = std::clamp(r / dr_ - 0.5, 0.0, static_cast<double>(v.size() - 1));
    const std::size_t i = std::min(static_cast<std::size_t>(s), v.size() - 2);
    const double f = s - static_cast<double>(i);
    return (1 - f) * v[i] + f * v[i + 1];
  }
  /// The monotonised-central limited slope from the differences on either side.
  static double limited(double left, double right) {
    if (left * right <= 0) return 0;
    const double m =
        std::min({2 * std::abs(left), 2 * std::abs(right), 0.5 * std::abs(left + right)});
    return left > 0 ? m : -m;
  }
  /// HLL flux (mass, momentum) between the states (hl, ul) and (hr, ur).
  static std::array<double, 2> hll(double hl, double ul, double hr, double ur) {
    const double cl = std::sqrt(kG * hl), cr = std::sqrt(kG * hr);
    // Einfeldt's speeds: the extremes of the sides' and the Roe average's
    const double sh = std::sqrt(hl) + std::sqrt(hr);
    const double u_roe = (std::sqrt(hl) * ul + std::sqrt(hr) * ur) / sh;
    const double c_roe = std::sqrt(0.5 * kG * (hl + hr));
    const double sl = std::min(ul - cl, u_roe - c_roe), sr = std::max(ur + cr, u_roe + c_roe);
    const std::array<double, 2> fl{hl * ul, hl * ul * ul + 0.5 * kG * hl * hl};
    const std::array<double, 2> fr{hr * ur, hr * ur * ur + 0.5 * kG * hr * hr};
    if (sl >= 0) return fl;
    if (sr <= 0) return fr;
    const std::array<double, 2> dl{hr - hl, hr * ur - hl * ul};
    return {(sr * fl[0] - sl * fr[0] + sl * sr * dl[0]) / (sr - sl),
            (sr * fl[1] - sl * fr[1] + sl * sr * dl[1]) / (sr - sl)};
  }
  /// One forward-Euler step of dt (s) of the finite-volume scheme, in place.
  void step(double dt) {
    const std::size_t n = h_.size();
    std::vector<double> u(n), sh(n), su(n);
    for (std::size_t i = 0; i < n; ++i) u[i] = q_[i] / h_[i];
    for (std::size_t i = 0; i < n; ++i) {
      // mirrors beyond r = 0 and the wall at r_max: the same depth, the velocity reversed
      const double hw = i ? h_[i - 1] : h_[i], uw = i ? u[i - 1] : -u[i];
      const double he = i + 1 < n ? h_[i + 1] : h_[i], ue = i + 1 < n ? u[i + 1] : -u[i];
      sh[i] = limited(h_[i] - hw, he - h_[i]);
      su[i] = limited(u[i] - uw, ue - u[i]);
    }
    // face f between cells f - 1 and f, at r = f dr
    std::vector<double> fm(n + 1), fq(n + 1);
    for (std::size_t f = 0; f <= n; ++f) {
      const bool wall_l = f == 0, wall_r = f == n;
      const double hr = wall_r ? 0 : h_[f] - 0.5 * sh[f], ur = wall_r ? 0 : u[f] - 0.5 * su[f];
      const double hl = wall_l ? 0 : h_[f - 1] + 0.5 * sh[f - 1];
      const double ul = wall_l ? 0 : u[f - 1] + 0.5 * su[f - 1];
      const auto flux = wall_l   ? hll(hr, -ur, hr, ur)
                        : wall_r ? hll(hl, ul, hl, -ul)
                                 : hll(hl, ul, hr, ur);
      const double length = cylindrical_ ? f * dr_ : 1.0;
      fm[f] = length * flux[0];
      fq[f] = length * flux[1];
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double volume = cylindrical_ ? (i + 0.5) * dr_ * dr_ : dr_;
      const double source = cylindrical_ ? 0.5 * kG * h_[i] * h_[i] * dr_ : 0.0;
      h_[i] -= dt / volume * (fm[i + 1] - fm[i]);
      q_[i] -= dt / volume * (fq[i + 1] - fq[i] - source);
    }
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

/// Green-Ampt (1911): the depth D (m) a ponded soil takes in t (s) from the infiltrated depth
/// F0 (m), the D with D - S ln(1 + D / (F0 + S)) = K t (K_sat in m/s, S = psi delta theta in m),
/// by bisection in long double (the difference cancels where D << S: 64-bit mantissas keep it
/// to 1e-14 relative over the tests' range).
inline double green_ampt_increment_exact(double f0, double t, double k, double s) {
  using ld = long double;
  const ld kt = static_cast<ld>(k) * t, a = static_cast<ld>(f0) + s;
  ld lo = kt, hi = kt + std::sqrt(2 * static_cast<ld>(s) * kt) + 1e-300L;
  for (int it = 0; it < 400; ++it) {
    const ld mid = 0.5L * (lo + hi);
    const ld g = mid - s * std::log1p(mid / a) - kt;
    (g > 0 ? hi : lo) = mid;
  }
  return static_cast<double>(0.5L * (lo + hi));
}

}  // namespace erodem::test
