// erodem — the values of the parameter schema (private to core/src; schema_values.cpp): the
// ranges of accepted values, where a value comes from, the readers of TOML nodes with their
// checks and error messages, and the formatters of dump_toml.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "erodem/schema.hpp"

namespace erodem::schema_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- ranges -----------------------------------------------------------------------------

/// An interval of accepted values; every check fails for NaN and infinities.
struct Range {
  double lo = -kInf;
  double hi = kInf;
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double x) const {
    if (!std::isfinite(x)) return false;
    if (lo_open ? !(x > lo) : !(x >= lo)) return false;
    if (hi_open ? !(x < hi) : !(x <= hi)) return false;
    return true;
  }

  /// E.g. ">= 0", "> 0", "in (0, 90)", "in [0, 1]"; "" when any finite value is accepted.
  std::string text() const {
    auto num = [](double v) {
      std::ostringstream os;
      os.precision(12);
      os << v;
      return os.str();
    };
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (has_lo && has_hi) {
      return std::string("in ") + (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) +
             (hi_open ? ")" : "]");
    }
    if (has_lo) return (lo_open ? "> " : ">= ") + num(lo);
    if (has_hi) return (hi_open ? "< " : "<= ") + num(hi);
    return "";
  }
};

Range any_finite();
Range at_least(double lo);
Range above(double lo);
Range closed(double lo, double hi);
Range open(double lo, double hi);
Range left_open(double lo, double hi);
Range right_open(double lo, double hi);

// ---- error context ----------------------------------------------------------------------

/// Where a value comes from: the source ("file.toml", "--set", "config") and the key.
struct Where {
  std::string source;
  std::string key;
  Error fail(const std::string& what) const { return config_error_in(source, key, what); }
  Where sub(const std::string& suffix) const { return Where{source, key + suffix}; }
};

/// The value of a node as TOML text, for "got ..." in error messages.
std::string node_text(const toml::node& n);

/// "a <noun> <range> (<si unit>, or a string like "<example>")".
std::string expected_quantity(Dimension dim, const Range& range);

// ---- readers: one TOML node into one C++ value, with checks ----------------------------

/// A number or quantity string of `dim` in `range`.
double read_double(const toml::node& n, Dimension dim, const Range& range, const Where& w);

/// Checks a stored double against its range (validate()).
void check_double(double v, Dimension dim, const Range& range, const Where& w);

/// An integer in `range` (an integral float such as 1e3 is accepted too).
long long read_integer(const toml::node& n, const Range& range, const Where& w);

bool read_bool(const toml::node& n, const Where& w);

std::string read_string(const toml::node& n, const Where& w);

const toml::array& read_array(const toml::node& n, const std::string& what, const Where& w);

/// [x, y]: two numbers of `dim`.
std::array<double, 2> read_pair(const toml::node& n, Dimension dim, const Range& second,
                                Dimension second_dim, const std::string& what, const Where& w);

/// [[t, value], ...] with t a time and value of `dim` in `range`.
Series read_series(const toml::node& n, Dimension dim, const Range& range, const Where& w);

/// [[x, y], ...] coordinates in the DEM's CRS.
std::vector<std::array<double, 2>> read_points(const toml::node& n, const Where& w);

// ---- checks of stored compound values (validate()) --------------------------------------

void check_series(const Series& s, Dimension dim, const Range& range, const Where& w);

void check_points(const std::vector<std::array<double, 2>>& pts, const Where& w);

// ---- formatting for dump_toml -----------------------------------------------------------

std::string format_pair(double a, double b);

std::string format_series(const Series& s);

std::string format_points(const std::vector<std::array<double, 2>>& pts);

}  // namespace erodem::schema_detail
