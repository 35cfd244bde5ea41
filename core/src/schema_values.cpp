// erodem — the values of the parameter schema (schema_values.hpp): quoted_string, ranges,
// the readers and checks of TOML values with their error messages, and the formatters.
#include "schema_values.hpp"

#include <cstdio>
#include <optional>
#include <sstream>

namespace erodem {

std::string quoted_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        // TOML basic strings hold no raw control character: U+0000..U+001F nor U+007F.
        if (static_cast<unsigned char>(c) < 0x20 || c == '\x7f') {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

namespace schema_detail {

Range any_finite() {
  return Range{};
}
Range at_least(double lo) {
  return Range{lo, kInf, false, false};
}
Range above(double lo) {
  return Range{lo, kInf, true, false};
}
Range closed(double lo, double hi) {
  return Range{lo, hi, false, false};
}
Range open(double lo, double hi) {
  return Range{lo, hi, true, true};
}
Range left_open(double lo, double hi) {
  return Range{lo, hi, true, false};
}
Range right_open(double lo, double hi) {
  return Range{lo, hi, false, true};
}

std::string node_text(const toml::node& n) {
  if (const auto str = n.value_exact<std::string>()) return quoted_string(*str);
  std::ostringstream os;
  n.visit([&os](auto&& v) { os << v; });
  return os.str();
}

std::string expected_quantity(Dimension dim, const Range& range) {
  std::string out = dimension_noun(dim);
  const std::string r = range.text();
  if (!r.empty()) out += " " + r;
  const std::string example = unit_example(dim);
  if (!example.empty()) {
    out += " (" + si_unit(dim) + ", or a string like \"" + example + "\")";
  } else if (dim == Dimension::manning) {
    out += " (" + si_unit(dim) + ")";
  }
  return out;
}

double read_double(const toml::node& n, Dimension dim, const Range& range, const Where& w) {
  double v = 0.0;
  if (auto i = n.value_exact<int64_t>()) {
    v = static_cast<double>(*i);
  } else if (auto f = n.value_exact<double>()) {
    v = *f;
  } else if (auto s = n.value_exact<std::string>()) {
    std::string why;
    const std::optional<double> q = try_parse_quantity(*s, dim, &why);
    if (!q) throw w.fail(why + "; expected " + expected_quantity(dim, range));
    v = *q;
  } else {
    throw w.fail("expected " + expected_quantity(dim, range) + ", got " + node_text(n));
  }
  if (!range.contains(v)) {
    throw w.fail("expected " + expected_quantity(dim, range) + ", got " + node_text(n));
  }
  return v;
}

void check_double(double v, Dimension dim, const Range& range, const Where& w) {
  if (!range.contains(v)) {
    throw w.fail("expected " + expected_quantity(dim, range) + ", got " + format_number(v));
  }
}

long long read_integer(const toml::node& n, const Range& range, const Where& w) {
  const std::string expected =
      "expected an integer" + (range.text().empty() ? "" : " " + range.text()) + ", got ";
  double v = 0.0;
  if (auto i = n.value_exact<int64_t>()) {
    v = static_cast<double>(*i);
  } else if (auto f = n.value_exact<double>(); f && std::isfinite(*f) && *f == std::floor(*f)) {
    v = *f;
  } else {
    throw w.fail(expected + node_text(n));
  }
  constexpr double kMaxExact = 9007199254740992.0;  // 2^53: larger values are not exact
  if (!range.contains(v) || !(std::abs(v) <= kMaxExact)) throw w.fail(expected + node_text(n));
  return static_cast<long long>(v);
}

bool read_bool(const toml::node& n, const Where& w) {
  if (auto b = n.value_exact<bool>()) return *b;
  throw w.fail("expected a boolean (true or false), got " + node_text(n));
}

std::string read_string(const toml::node& n, const Where& w) {
  if (auto s = n.value_exact<std::string>()) return *s;
  throw w.fail("expected a string, got " + node_text(n));
}

const toml::array& read_array(const toml::node& n, const std::string& what, const Where& w) {
  if (const toml::array* a = n.as_array()) return *a;
  throw w.fail("expected " + what + ", got " + node_text(n));
}

std::array<double, 2> read_pair(const toml::node& n, Dimension dim, const Range& second,
                                Dimension second_dim, const std::string& what, const Where& w) {
  const toml::array& a = read_array(n, what, w);
  if (a.size() != 2) throw w.fail("expected " + what + ", got " + node_text(n));
  return {read_double(*a.get(0), dim, any_finite(), w.sub("[0]")),
          read_double(*a.get(1), second_dim, second, w.sub("[1]"))};
}

Series read_series(const toml::node& n, Dimension dim, const Range& range, const Where& w) {
  const std::string what = "an array of [time, value] pairs";
  const toml::array& a = read_array(n, what, w);
  Series out;
  for (size_t i = 0; i < a.size(); ++i) {
    const auto pair = read_pair(*a.get(i), Dimension::time, range, dim, "a [time, value] pair",
                                w.sub("[" + std::to_string(i) + "]"));
    out.push_back({pair[0], pair[1]});
  }
  return out;
}

std::vector<std::array<double, 2>> read_points(const toml::node& n, const Where& w) {
  const toml::array& a = read_array(n, "an array of [x, y] points", w);
  std::vector<std::array<double, 2>> out;
  for (size_t i = 0; i < a.size(); ++i) {
    out.push_back(read_pair(*a.get(i), Dimension::dimensionless, any_finite(),
                            Dimension::dimensionless, "an [x, y] point",
                            w.sub("[" + std::to_string(i) + "]")));
  }
  return out;
}

void check_series(const Series& s, Dimension dim, const Range& range, const Where& w) {
  for (size_t i = 0; i < s.size(); ++i) {
    const Where wi = w.sub("[" + std::to_string(i) + "]");
    check_double(s[i].t, Dimension::time, any_finite(), wi);
    check_double(s[i].value, dim, range, wi);
    if (i > 0 && !(s[i].t > s[i - 1].t)) {
      throw wi.fail("times must increase, got " + format_number(s[i].t) + " after " +
                    format_number(s[i - 1].t));
    }
  }
}

void check_points(const std::vector<std::array<double, 2>>& pts, const Where& w) {
  for (size_t i = 0; i < pts.size(); ++i) {
    for (double c : pts[i]) {
      check_double(c, Dimension::dimensionless, any_finite(), w.sub("[" + std::to_string(i) + "]"));
    }
  }
}

std::string format_pair(double a, double b) {
  return "[" + format_number(a) + ", " + format_number(b) + "]";
}

std::string format_series(const Series& s) {
  std::string out = "[";
  for (size_t i = 0; i < s.size(); ++i) {
    out += (i ? ", " : "") + format_pair(s[i].t, s[i].value);
  }
  return out + "]";
}

std::string format_points(const std::vector<std::array<double, 2>>& pts) {
  std::string out = "[";
  for (size_t i = 0; i < pts.size(); ++i) {
    out += (i ? ", " : "") + format_pair(pts[i][0], pts[i][1]);
  }
  return out + "]";
}

}  // namespace schema_detail

}  // namespace erodem
