// erodem — the parameter schema: one descriptor per key (see schema.hpp). The table in
// descriptor_table() is the only place where keys, ranges, units and docs are written;
// parsing, `--set`, validation, dumping and --help are all derived from it.
#include "erodem/schema.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

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
        if (static_cast<unsigned char>(c) < 0x20) {
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

namespace {

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

// ---- error context ----------------------------------------------------------------------

/// Where a value comes from: the source ("file.toml", "--set", "config") and the key.
struct Where {
  std::string source;
  std::string key;
  Error fail(const std::string& what) const { return config_error_in(source, key, what); }
  Where sub(const std::string& suffix) const { return Where{source, key + suffix}; }
};

/// The value of a node as TOML text, for "got ..." in error messages.
std::string node_text(const toml::node& n) {
  if (const auto str = n.value_exact<std::string>()) return quoted_string(*str);
  std::ostringstream os;
  n.visit([&os](auto&& v) { os << v; });
  return os.str();
}

/// "a <noun> <range> (<si unit>, or a string like "<example>")".
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

// ---- readers: one TOML node into one C++ value, with checks ----------------------------

/// A number or quantity string of `dim` in `range`.
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

/// Checks a stored double against its range (validate()).
void check_double(double v, Dimension dim, const Range& range, const Where& w) {
  if (!range.contains(v)) {
    throw w.fail("expected " + expected_quantity(dim, range) + ", got " + format_number(v));
  }
}

/// An integer in `range` (an integral float such as 1e3 is accepted too).
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

/// [x, y]: two numbers of `dim`.
std::array<double, 2> read_pair(const toml::node& n, Dimension dim, const Range& second,
                                Dimension second_dim, const std::string& what, const Where& w) {
  const toml::array& a = read_array(n, what, w);
  if (a.size() != 2) throw w.fail("expected " + what + ", got " + node_text(n));
  return {read_double(*a.get(0), dim, any_finite(), w.sub("[0]")),
          read_double(*a.get(1), second_dim, second, w.sub("[1]"))};
}

/// [[t, value], ...] with t a time and value of `dim` in `range`.
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

/// [[x, y], ...] coordinates in the DEM's CRS.
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

// ---- checks of stored compound values (validate()) --------------------------------------

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

// ---- formatting for dump_toml -----------------------------------------------------------

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

// ---- descriptors ------------------------------------------------------------------------

/// One parameter: its key, what it accepts, its doc, and how to read, check, print and
/// reset its value in a Params.
struct Descriptor {
  std::string key;
  std::string type;
  Dimension dim = Dimension::dimensionless;
  std::string accepted;
  std::string doc;
  std::function<void(Params&, const toml::node&, const Where&)> assign;
  std::function<void(const Params&, const Where&)> check;
  /// TOML value text; nullopt for an unset optional value.
  std::function<std::optional<std::string>(const Params&)> format;
  std::function<void(Params&)> reset;  ///< back to the default
};

/// Common part of all descriptors: the reset to the default-constructed value.
template <class Access>
Descriptor base(const char* key, Access access, std::string type, Dimension dim,
                std::string accepted, const char* doc) {
  Descriptor d;
  d.key = key;
  d.type = std::move(type);
  d.dim = dim;
  d.accepted = std::move(accepted);
  d.doc = doc;
  d.reset = [access](Params& p) {
    const Params defaults;
    access(p) = access(defaults);
  };
  return d;
}

template <class Access>
Descriptor number(const char* key, Access access, Dimension dim, Range range, const char* doc) {
  Descriptor d = base(key, access, "number", dim, range.text(), doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    access(p) = read_double(n, dim, range, w);
  };
  d.check = [=](const Params& p, const Where& w) { check_double(access(p), dim, range, w); };
  d.format = [=](const Params& p) { return format_number(access(p)); };
  return d;
}

template <class Access>
Descriptor integer(const char* key, Access access, Range range, const char* doc) {
  Descriptor d = base(key, access, "integer", Dimension::dimensionless, range.text(), doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    using T = std::remove_reference_t<decltype(access(p))>;
    access(p) = static_cast<T>(read_integer(n, range, w));
  };
  d.check = [=](const Params& p, const Where& w) {
    if (!range.contains(static_cast<double>(access(p)))) {
      throw w.fail("expected an integer " + range.text() + ", got " + std::to_string(access(p)));
    }
  };
  d.format = [=](const Params& p) { return std::to_string(access(p)); };
  return d;
}

template <class Access>
Descriptor boolean(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "boolean", Dimension::dimensionless, "true | false", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) { access(p) = read_bool(n, w); };
  d.check = [](const Params&, const Where&) {};
  d.format = [=](const Params& p) { return std::string(access(p) ? "true" : "false"); };
  return d;
}

template <class Access>
Descriptor text(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "string", Dimension::dimensionless, "any string", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) { access(p) = read_string(n, w); };
  d.check = [](const Params&, const Where&) {};
  d.format = [=](const Params& p) { return quoted_string(access(p)); };
  return d;
}

/// Names and values of a choice (an enum, or a string restricted to a list).
template <class T>
using Choices = std::vector<std::pair<std::string, T>>;

template <class T>
std::string choices_text(const Choices<T>& choices) {
  std::string out;
  for (const auto& [name, value] : choices) {
    out += (out.empty() ? "" : " | ") + (name.empty() ? std::string("\"\"") : name);
  }
  return out;
}

template <class T>
std::string choice_name(const Choices<T>& choices, const T& value) {
  for (const auto& [name, v] : choices) {
    if (v == value) return name;
  }
  return "?";
}

template <class T, class Access>
Descriptor choice(const char* key, Access access, Choices<T> choices, const char* doc) {
  Descriptor d = base(key, access, "choice", Dimension::dimensionless, choices_text(choices), doc);
  const std::string accepted = d.accepted;
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    const auto s = n.value_exact<std::string>();
    if (s) {
      for (const auto& [name, value] : choices) {
        if (*s == name) {
          access(p) = value;
          return;
        }
      }
    }
    throw w.fail("expected one of " + accepted + ", got " + node_text(n));
  };
  d.check = [=](const Params& p, const Where& w) {
    for (const auto& [name, value] : choices) {
      if (access(p) == value) return;
    }
    throw w.fail("expected one of " + accepted);
  };
  d.format = [=](const Params& p) { return quoted_string(choice_name(choices, access(p))); };
  return d;
}

/// An optional number: unset by default; the string "none" unsets it.
template <class Access>
Descriptor optional_number(const char* key, Access access, Dimension dim, Range range,
                           const char* doc) {
  Descriptor d =
      base(key, access, "optional number", dim,
           (range.text().empty() ? std::string("number") : range.text()) + ", or \"none\"", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    if (n.value_exact<std::string>() == std::optional<std::string>("none")) {
      access(p).reset();
    } else {
      access(p) = read_double(n, dim, range, w);
    }
  };
  d.check = [=](const Params& p, const Where& w) {
    if (access(p)) check_double(*access(p), dim, range, w);
  };
  d.format = [=](const Params& p) -> std::optional<std::string> {
    if (!access(p)) return std::nullopt;
    return format_number(*access(p));
  };
  return d;
}

/// A number, or a string path of a raster on the DEM grid.
template <class Access>
Descriptor scalar_or_raster(const char* key, Access access, Dimension dim, Range range,
                            const char* doc) {
  Descriptor d = base(
      key, access, "number or raster path", dim,
      (range.text().empty() ? std::string("number") : range.text()) + ", or a raster path", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    const auto s = n.value_exact<std::string>();
    if (s && !s->empty() && !looks_like_quantity(*s)) {
      access(p) = ScalarOrRaster{0.0, *s};
    } else {
      access(p) = ScalarOrRaster{read_double(n, dim, range, w), {}};
    }
  };
  d.check = [=](const Params& p, const Where& w) {
    if (!access(p).is_raster()) check_double(access(p).value, dim, range, w);
  };
  d.format = [=](const Params& p) {
    return access(p).is_raster() ? quoted_string(access(p).path) : format_number(access(p).value);
  };
  return d;
}

/// A time series [[t, value], ...] with increasing times.
template <class Access>
Descriptor series(const char* key, Access access, Dimension dim, Range range, const char* doc) {
  Descriptor d = base(key, access, "series", dim,
                      "[[time, value], ...], times increasing, values " + range.text(), doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    Series s = read_series(n, dim, range, w);
    check_series(s, dim, range, w);
    access(p) = std::move(s);
  };
  d.check = [=](const Params& p, const Where& w) { check_series(access(p), dim, range, w); };
  d.format = [=](const Params& p) { return format_series(access(p)); };
  return d;
}

/// A list of [x, y] points in the DEM's CRS.
template <class Access>
Descriptor points(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "points", Dimension::dimensionless, "[[x, y], ...]", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) { access(p) = read_points(n, w); };
  d.check = [=](const Params& p, const Where& w) { check_points(access(p), w); };
  d.format = [=](const Params& p) { return format_points(access(p)); };
  return d;
}

/// A list of distinct names, each from `allowed`.
template <class Access>
Descriptor name_list(const char* key, Access access, std::vector<std::string> allowed,
                     const char* doc) {
  std::string accepted;
  for (const std::string& a : allowed) accepted += (accepted.empty() ? "" : ", ") + a;
  Descriptor d = base(key, access, "list of names", Dimension::dimensionless,
                      "distinct names from: " + accepted, doc);
  auto check_names = [=](const std::vector<std::string>& names, const Where& w) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (std::find(allowed.begin(), allowed.end(), names[i]) == allowed.end()) {
        throw w.fail("unknown name \"" + names[i] + "\"; accepted: " + accepted);
      }
      if (std::find(names.begin(), names.begin() + static_cast<long>(i), names[i]) !=
          names.begin() + static_cast<long>(i)) {
        throw w.fail("\"" + names[i] + "\" is listed twice");
      }
    }
  };
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    const toml::array& a = read_array(n, "an array of names from: " + accepted, w);
    std::vector<std::string> names;
    for (size_t i = 0; i < a.size(); ++i) {
      names.push_back(read_string(*a.get(i), w.sub("[" + std::to_string(i) + "]")));
    }
    check_names(names, w);
    access(p) = std::move(names);
  };
  d.check = [=](const Params& p, const Where& w) { check_names(access(p), w); };
  d.format = [=](const Params& p) {
    std::string out = "[";
    for (size_t i = 0; i < access(p).size(); ++i)
      out += (i ? ", " : "") + quoted_string(access(p)[i]);
    return out + "]";
  };
  return d;
}

/// dem.window: [col, row, width, height] in pixels; "none" unsets it.
template <class Access>
Descriptor window(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "window", Dimension::dimensionless,
                      "[col >= 0, row >= 0, width > 0, height > 0], or \"none\"", doc);
  static const char* names[4] = {"col", "row", "width", "height"};
  auto check_window = [](const std::array<int, 4>& v, const Where& w) {
    for (int i = 0; i < 4; ++i) {
      const bool ok = i < 2 ? v[i] >= 0 : v[i] > 0;
      if (!ok) {
        throw w.fail(std::string("expected ") + names[i] + (i < 2 ? " >= 0" : " > 0") +
                     " in [col, row, width, height], got " + std::to_string(v[i]));
      }
    }
  };
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    if (n.value_exact<std::string>() == std::optional<std::string>("none")) {
      access(p).reset();
      return;
    }
    const std::string what = "[col, row, width, height] in pixels";
    const toml::array& a = read_array(n, what, w);
    if (a.size() != 4) throw w.fail("expected " + what + ", got " + node_text(n));
    std::array<int, 4> v{};
    for (size_t i = 0; i < 4; ++i) {
      v[i] = static_cast<int>(
          read_integer(*a.get(i), closed(-1e9, 1e9), w.sub("[" + std::to_string(i) + "]")));
    }
    check_window(v, w);
    access(p) = v;
  };
  d.check = [=](const Params& p, const Where& w) {
    if (access(p)) check_window(*access(p), w);
  };
  d.format = [=](const Params& p) -> std::optional<std::string> {
    if (!access(p)) return std::nullopt;
    const auto& v = *access(p);
    return "[" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) +
           ", " + std::to_string(v[3]) + "]";
  };
  return d;
}

/// dem.resample: a length (float or "320 m") -> dem.resample, an integer -> resample_factor.
Descriptor resample_descriptor(const char* key, const char* doc) {
  auto access = [](auto& p) -> auto& {
    return p.dem;
  };
  Descriptor d = base(key, access, "length or integer", Dimension::length,
                      "a cell size >= 0 (m, or a string like \"320 m\"), or an integer "
                      "factor >= 0; 0 = none",
                      doc);
  d.reset = [](Params& p) {
    p.dem.resample = Params{}.dem.resample;
    p.dem.resample_factor = Params{}.dem.resample_factor;
  };
  d.assign = [](Params& p, const toml::node& n, const Where& w) {
    if (n.is_integer()) {
      p.dem.resample_factor = static_cast<int>(read_integer(n, closed(0, 1e6), w));
      p.dem.resample = 0.0;
    } else {
      p.dem.resample = read_double(n, Dimension::length, at_least(0), w);
      p.dem.resample_factor = 0;
    }
  };
  d.check = [](const Params& p, const Where& w) {
    check_double(p.dem.resample, Dimension::length, at_least(0), w);
    if (p.dem.resample_factor < 0) throw w.fail("the resample factor must be >= 0");
    if (p.dem.resample > 0 && p.dem.resample_factor > 0) {
      throw w.fail("give a resample cell size or an integer factor, not both");
    }
  };
  d.format = [](const Params& p) {
    return p.dem.resample_factor > 0 || p.dem.resample == 0.0
               ? std::to_string(p.dem.resample_factor)
               : format_number(p.dem.resample);
  };
  return d;
}

/// flow.pipe_length: "cell" (stored as 0) or a length > 0.
Descriptor pipe_length_descriptor(const char* key, const char* doc) {
  auto access = [](auto& p) -> auto& {
    return p.flow.pipe_length;
  };
  Descriptor d = base(key, access, "length or \"cell\"", Dimension::length,
                      "\"cell\" (the cell size), or a length >= 0 (0 = the cell size)", doc);
  d.assign = [](Params& p, const toml::node& n, const Where& w) {
    if (n.value_exact<std::string>() == std::optional<std::string>("cell")) {
      p.flow.pipe_length = 0.0;
    } else {
      p.flow.pipe_length = read_double(n, Dimension::length, at_least(0), w);
    }
  };
  d.check = [](const Params& p, const Where& w) {
    check_double(p.flow.pipe_length, Dimension::length, at_least(0), w);
  };
  d.format = [](const Params& p) {
    return p.flow.pipe_length == 0.0 ? quoted_string("cell") : format_number(p.flow.pipe_length);
  };
  return d;
}

// ---- inflow -----------------------------------------------------------------------------

const Range kDischargeRange = at_least(0);

void check_inflow(const InflowSpec& in, const Where& w) {
  if (in.vertices.empty()) throw w.fail("needs a point = [x, y] or a line = [[x, y], ...]");
  check_points(in.vertices, w.sub(in.vertices.size() == 1 ? ".point" : ".line"));
  if (in.hydrograph.empty()) throw w.sub(".hydrograph").fail("needs at least one [t, Q] pair");
  check_series(in.hydrograph, Dimension::discharge, kDischargeRange, w.sub(".hydrograph"));
}

/// One inflow table: point = [x, y] or line = [[x, y], ...], and hydrograph = [[t, Q], ...].
InflowSpec read_inflow(const toml::node& n, const Where& w) {
  const toml::table* t = n.as_table();
  if (!t) throw w.fail("expected a table with point or line, and hydrograph; got " + node_text(n));
  InflowSpec in;
  bool has_point = false;
  bool has_line = false;
  for (auto&& [k, v] : *t) {
    const std::string name(k.str());
    const Where wk = w.sub("." + name);
    if (name == "point") {
      const auto xy = read_pair(v, Dimension::dimensionless, any_finite(), Dimension::dimensionless,
                                "an [x, y] point", wk);
      in.vertices = {xy};
      has_point = true;
    } else if (name == "line") {
      in.vertices = read_points(v, wk);
      if (in.vertices.size() < 2) throw wk.fail("a line needs two or more [x, y] vertices");
      has_line = true;
    } else if (name == "hydrograph") {
      in.hydrograph = read_series(v, Dimension::discharge, kDischargeRange, wk);
    } else {
      throw wk.fail("unknown inflow key; accepted: point, line, hydrograph");
    }
  }
  if (has_point && has_line) throw w.fail("give a point or a line, not both");
  check_inflow(in, w);
  return in;
}

Descriptor inflow_descriptor(const char* key, const char* doc) {
  auto access = [](auto& p) -> auto& {
    return p.inflow;
  };
  Descriptor d = base(key, access, "inflow list", Dimension::discharge,
                      "[[inflow]] tables: point = [x, y] or line = [[x, y], ...], "
                      "hydrograph = [[t, Q], ...] with Q >= 0 (m^3/s)",
                      doc);
  d.assign = [](Params& p, const toml::node& n, const Where& w) {
    const toml::array& a = read_array(n, "an array of inflow tables ([[inflow]])", w);
    std::vector<InflowSpec> list;
    for (size_t i = 0; i < a.size(); ++i) {
      list.push_back(read_inflow(*a.get(i), w.sub("[" + std::to_string(i) + "]")));
    }
    p.inflow = std::move(list);
  };
  d.check = [](const Params& p, const Where& w) {
    for (size_t i = 0; i < p.inflow.size(); ++i) {
      check_inflow(p.inflow[i], w.sub("[" + std::to_string(i) + "]"));
    }
  };
  d.format = [](const Params&) -> std::optional<std::string> { return std::nullopt; };
  return d;
}

/// The [[inflow]] tables of dump_toml.
std::string format_inflow_tables(const std::vector<InflowSpec>& list, const std::string& doc) {
  std::string out = "\n# " + doc + "\n";
  if (list.empty()) return out + "# (no [[inflow]] tables)\n";
  for (const InflowSpec& in : list) {
    out += "[[inflow]]\n";
    if (in.vertices.size() == 1) {
      out += "point = " + format_pair(in.vertices[0][0], in.vertices[0][1]) + "\n";
    } else {
      out += "line = " + format_points(in.vertices) + "\n";
    }
    out += "hydrograph = " + format_series(in.hydrograph) + "\n";
  }
  return out;
}

// ---- the table --------------------------------------------------------------------------

/// The dotted key and an accessor for a Params member, e.g. FIELD(time.dt).
#define ERODEM_FIELD(member)      \
#member, [](auto& p) -> auto& { \
    return p.member;              \
  }

/// Every parameter, grouped by section (sections must be contiguous for dump_toml).
const std::vector<Descriptor>& descriptor_table() {
  using D = Dimension;
  static const Choices<BoundaryKind> boundary{{"closed", BoundaryKind::closed},
                                              {"open", BoundaryKind::open},
                                              {"fixed_level", BoundaryKind::fixed_level}};
  static const std::vector<Descriptor> table{
      text(ERODEM_FIELD(dem.path), "DEM file (GDAL raster); relative to the config file"),
      choice(ERODEM_FIELD(dem.synthetic),
             Choices<std::string>{{"", ""},
                                  {"fbm", "fbm"},
                                  {"ridged", "ridged"},
                                  {"diamond_square", "diamond_square"},
                                  {"hill", "hill"},
                                  {"lake", "lake"},
                                  {"valley", "valley"},
                                  {"ridge", "ridge"}},
             "synthetic terrain generator instead of a DEM file (\"\" = none)"),
      integer(ERODEM_FIELD(dem.size), closed(2, 32768),
              "synthetic terrain: grid size (cells per side)"),
      integer(ERODEM_FIELD(dem.seed), closed(-2147483648.0, 2147483647.0),
              "synthetic terrain: random seed"),
      number(ERODEM_FIELD(dem.relief), D::length, above(0),
             "synthetic terrain: elevation range (m)"),
      window(ERODEM_FIELD(dem.window), "pixel window [col, row, width, height] of the DEM"),
      resample_descriptor("dem.resample",
                          "coarser cell size by averaging (m), or an integer factor; 0 = none"),
      number(ERODEM_FIELD(dem.z_scale), D::dimensionless, above(0),
             "multiplier of the stored elevations (1)"),
      number(ERODEM_FIELD(dem.cell_size), D::length, at_least(0),
             "cell size (m) for files without georeferencing and synthetic terrain; 0 = from "
             "the file"),
      text(ERODEM_FIELD(dem.crs), "CRS (e.g. \"EPSG:32610\") for files without georeferencing"),
      optional_number(ERODEM_FIELD(dem.nodata_value), D::dimensionless, any_finite(),
                      "stored value to treat as nodata, in the file's units before z_scale "
                      "(e.g. 0 for a heightmap whose sea is 0; with boundary.nodata = \"sea\" "
                      "such cells hold the sea level)"),

      optional_number(ERODEM_FIELD(initial.water_level), D::length, any_finite(),
                      "fill every active cell up to this water surface elevation (m)"),
      scalar_or_raster(ERODEM_FIELD(initial.water_depth), D::length, at_least(0),
                       "initial water depth (m), uniform or a raster path"),

      integer(ERODEM_FIELD(time.steps), at_least(1),
              "number of steps (used when time.duration is 0)"),
      number(ERODEM_FIELD(time.duration), D::time, at_least(0),
             "simulated time (s); 0 = use time.steps"),
      number(ERODEM_FIELD(time.dt), D::time, above(0), "fixed time step (s)"),
      boolean(ERODEM_FIELD(time.adaptive), "CFL-adaptive time step"),
      number(ERODEM_FIELD(time.cfl), D::dimensionless, left_open(0, 1),
             "Courant number alpha of the adaptive step (1)"),
      number(ERODEM_FIELD(time.dt_max), D::time, above(0), "upper bound of the adaptive step (s)"),

      choice(ERODEM_FIELD(flow.scheme),
             Choices<FlowScheme>{{"pipes", FlowScheme::pipes},
                                 {"local_inertial", FlowScheme::local_inertial}},
             "flow scheme: pipes (Mei 2007) or local_inertial (Bates 2010)"),
      scalar_or_raster(ERODEM_FIELD(flow.manning_n), D::manning, at_least(0),
                       "Manning roughness n (s m^-1/3), uniform or a raster path"),
      number(ERODEM_FIELD(flow.theta), D::dimensionless, closed(0, 1),
             "local_inertial: de Almeida weighting theta (1)"),
      number(ERODEM_FIELD(flow.pipe_area), D::area, above(0), "pipes: pipe cross-section A (m^2)"),
      pipe_length_descriptor("flow.pipe_length",
                             "pipes: pipe length l (m), or \"cell\" for the cell size"),
      number(ERODEM_FIELD(flow.gravity), D::acceleration, above(0),
             "gravitational acceleration g (m/s^2)"),

      number(ERODEM_FIELD(rain.rate), D::speed, at_least(0),
             "uniform rain rate (m/s), used when rain.series is empty"),
      series(ERODEM_FIELD(rain.series), D::speed, at_least(0),
             "rain rate series [[time (s), rate (m/s)], ...], linear in between, held at the end "
             "values outside"),
      text(ERODEM_FIELD(rain.raster), "raster path of a spatial rain multiplier (1); \"\" = none"),

      inflow_descriptor("inflow",
                        "point or line inflows with a hydrograph [[time (s), discharge (m^3/s)]]"),

      boolean(ERODEM_FIELD(erosion.enabled), "hydraulic erosion and deposition"),
      number(ERODEM_FIELD(erosion.sediment_capacity), D::time, at_least(0),
             "sediment capacity K_c (s): capacity per unit speed and tilt"),
      number(ERODEM_FIELD(erosion.dissolving_rate), D::inverse_time, at_least(0),
             "dissolving (erosion) rate K_s (1/s)"),
      number(ERODEM_FIELD(erosion.deposition_rate), D::inverse_time, at_least(0),
             "deposition rate K_d (1/s)"),
      number(ERODEM_FIELD(erosion.min_tilt), D::dimensionless, closed(0, 1),
             "minimum tilt sin_min in the capacity (1)"),
      scalar_or_raster(ERODEM_FIELD(erosion.hardness), D::dimensionless, closed(0, 1),
                       "hardness R in [0, 1] (1), uniform or a raster path"),
      number(ERODEM_FIELD(erosion.min_depth), D::length, at_least(0),
             "depth below which the capacity ramps to 0 (m); 0 = off"),
      optional_number(ERODEM_FIELD(erosion.bedrock_level), D::length, any_finite(),
                      "no erosion below this bed elevation (m)"),

      choice(ERODEM_FIELD(transport.scheme),
             Choices<TransportScheme>{{"conservative", TransportScheme::conservative},
                                      {"semi_lagrangian", TransportScheme::semi_lagrangian}},
             "sediment transport: conservative (flux form) or semi_lagrangian (Mei 2007)"),

      boolean(ERODEM_FIELD(thermal.enabled), "thermal erosion (slope collapse)"),
      number(ERODEM_FIELD(thermal.talus_angle), D::angle, open(0, 90), "talus angle (degrees)"),
      number(ERODEM_FIELD(thermal.rate), D::inverse_time, at_least(0), "thermal rate K_t (1/s)"),

      number(ERODEM_FIELD(evaporation.rate), D::inverse_time, at_least(0),
             "evaporation rate K_e (1/s)"),

      choice(ERODEM_FIELD(boundary.north), boundary, "north edge: closed, open or fixed_level"),
      choice(ERODEM_FIELD(boundary.south), boundary, "south edge: closed, open or fixed_level"),
      choice(ERODEM_FIELD(boundary.east), boundary, "east edge: closed, open or fixed_level"),
      choice(ERODEM_FIELD(boundary.west), boundary, "west edge: closed, open or fixed_level"),
      number(ERODEM_FIELD(boundary.sea_level), D::length, any_finite(),
             "water level of fixed_level edges and sea nodata cells (m)"),
      choice(ERODEM_FIELD(boundary.nodata),
             Choices<NodataKind>{{"wall", NodataKind::wall}, {"sea", NodataKind::sea}},
             "nodata cells: wall, or sea at boundary.sea_level"),

      text(ERODEM_FIELD(output.path), "result file (.h5)"),
      integer(ERODEM_FIELD(output.every), at_least(1),
              "steps between snapshots (used when output.interval is 0)"),
      number(ERODEM_FIELD(output.interval), D::time, at_least(0),
             "simulated time between snapshots (s); 0 = use output.every"),
      name_list(ERODEM_FIELD(output.fields),
                {"bed", "water_depth", "sediment", "velocity_x", "velocity_y", "erosion", "wetness",
                 "hardness", "flux_left", "flux_right", "flux_top", "flux_bottom"},
                "fields written in each snapshot"),
      points(ERODEM_FIELD(output.gauges),
             "gauge points [[x, y], ...] in the DEM's CRS: depth, level and speed every step"),
      boolean(ERODEM_FIELD(output.restart_state),
              "store the full state at each snapshot, so a run can restart from it"),

      choice(ERODEM_FIELD(numerics.precision),
             Choices<Precision>{{"float32", Precision::float32}, {"float64", Precision::float64}},
             "floating-point precision of the CPU reference: float32 or float64"),
      number(
          ERODEM_FIELD(numerics.dry_depth), D::length, at_least(0),
          "local_inertial: faces shallower than this carry no flow (m); below 1e-16 m none does"),
      number(ERODEM_FIELD(numerics.velocity_min_depth), D::length, at_least(0),
             "velocity is 0 below this mean depth d_min (m)"),
      number(ERODEM_FIELD(numerics.wetness_time), D::time, above(0),
             "time constant of the wetness running mean (s)"),
      integer(ERODEM_FIELD(numerics.threads), closed(0, 65536), "CPU threads (0 = all cores)"),
  };
  return table;
}

#undef ERODEM_FIELD

const Descriptor* find_descriptor(const std::string& key) {
  for (const Descriptor& d : descriptor_table()) {
    if (d.key == key) return &d;
  }
  return nullptr;
}

/// True when `key` names a table of parameters, e.g. "rain".
bool is_section(const std::string& key) {
  for (const Descriptor& d : descriptor_table()) {
    if (d.key.compare(0, key.size() + 1, key + ".") == 0) return true;
  }
  return false;
}

std::string section_of(const std::string& key) {
  const size_t dot = key.find('.');
  return dot == std::string::npos ? std::string() : key.substr(0, dot);
}

std::string leaf_of(const std::string& key) {
  const size_t dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1);
  std::vector<size_t> cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, subst});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

Error unknown_key_error(const std::string& source, const std::string& key) {
  const std::string hint = closest_parameter_key(key);
  return config_error_in(
      source, key,
      "unknown parameter" + (hint.empty() ? std::string() : "; did you mean '" + hint + "'?"));
}

/// An unknown table such as [rian]: suggests the closest known table.
Error unknown_table_error(const std::string& source, const std::string& key) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const Descriptor& d : descriptor_table()) {
    const std::string section = d.key.substr(0, d.key.find('.'));
    const size_t distance = edit_distance(key, section);
    if (distance < best_distance) {
      best_distance = distance;
      best = section;
    }
  }
  const bool close = best_distance <= std::max<size_t>(2, key.size() / 4);
  return config_error_in(
      source, key, "unknown table" + (close ? "; did you mean [" + best + "]?" : std::string()));
}

const Descriptor& require_descriptor(const std::string& key, const std::string& source) {
  const Descriptor* d = find_descriptor(key);
  if (!d) throw unknown_key_error(source, key);
  return *d;
}

/// Applies every key of table `t` (whose dotted prefix is `prefix`) to `p`.
void apply_table(Params& p, const toml::table& t, const std::string& prefix,
                 const std::string& source) {
  for (auto&& [k, node] : t) {
    const std::string key =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const Descriptor* d = find_descriptor(key)) {
      d->assign(p, node, Where{source, key});
    } else if (is_section(key)) {
      const toml::table* sub = node.as_table();
      if (!sub) {
        throw config_error_in(
            source, key, "expected a table of parameters [" + key + "], got " + node_text(node));
      }
      apply_table(p, *sub, key, source);
    } else if (node.is_table()) {
      throw unknown_table_error(source, key);
    } else {
      throw unknown_key_error(source, key);
    }
  }
}

/// --set alternatives: setting the first key resets the others, so the last one wins.
const std::vector<std::pair<std::string, std::vector<std::string>>>& alternatives() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> alt{
      {"time.steps", {"time.duration"}},
      {"output.every", {"output.interval"}},
      {"rain.rate", {"rain.series"}},
      {"rain.series", {"rain.rate"}},
      {"dem.path", {"dem.synthetic"}},
      {"dem.synthetic", {"dem.path"}},
      {"initial.water_level", {"initial.water_depth"}},
      {"initial.water_depth", {"initial.water_level"}},
  };
  return alt;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// Parses `text` as one TOML value; nullopt when it is not valid TOML.
std::optional<toml::table> parse_toml_value(const std::string& text) {
  try {
    toml::table doc = toml::parse("value = " + text + "\n");
    if (doc.size() == 1 && doc.contains("value")) return doc;
  } catch (const toml::parse_error&) {
  }
  return std::nullopt;
}

void check_cross_fields(const Params& p, const std::string& source) {
  auto fail = [&](const std::string& key, const std::string& what) {
    return config_error_in(source, key, what);
  };
  if (p.dem.path.empty() && p.dem.synthetic.empty()) {
    throw fail("dem.path", "a DEM is required: give dem.path (a raster file) or dem.synthetic");
  }
  if (!p.dem.path.empty() && !p.dem.synthetic.empty()) {
    throw fail("dem.path", "give dem.path or dem.synthetic, not both");
  }
  if (p.initial.water_level &&
      (p.initial.water_depth.is_raster() || p.initial.water_depth.value != 0.0)) {
    throw fail("initial.water_level", "give initial.water_level or initial.water_depth, not both");
  }
  if (p.rain.rate != 0.0 && !p.rain.series.empty()) {
    throw fail("rain.rate", "give rain.rate or rain.series, not both");
  }
  if (p.output.path.empty()) throw fail("output.path", "must not be empty");
}

}  // namespace

// ---- public API -------------------------------------------------------------------------

Params params_from_toml(const toml::table& t, const std::string& source_name) {
  Params p;
  apply_table(p, t, "", source_name);
  return p;
}

void apply_setting(Params& p, const std::string& key_text, const std::string& value_text) {
  const std::string source = "--set";
  const std::string key = trim(key_text);
  const Descriptor& d = require_descriptor(key, source);
  const Where where{source, key};
  const std::optional<toml::table> doc = parse_toml_value(value_text);
  const toml::node* node = doc ? doc->get("value") : nullptr;
  const bool wants_text = d.type == "string" || d.type == "choice";
  if (node && !(wants_text && !node->is_string())) {
    d.assign(p, *node, where);
  } else {
    d.assign(p, toml::value<std::string>(trim(value_text)), where);
  }
  for (const auto& [first, others] : alternatives()) {
    if (first != key) continue;
    for (const std::string& other : others) find_descriptor(other)->reset(p);
  }
}

void apply_setting(Params& p, const std::string& key_equals_value) {
  const size_t eq = key_equals_value.find('=');
  if (eq == std::string::npos) {
    throw Error(ExitCode::config, "--set: expected key=value, got '" + key_equals_value + "'");
  }
  apply_setting(p, key_equals_value.substr(0, eq), key_equals_value.substr(eq + 1));
}

void validate(const Params& p, const std::string& source_name) {
  for (const Descriptor& d : descriptor_table()) d.check(p, Where{source_name, d.key});
  check_cross_fields(p, source_name);
}

std::string dump_toml(const Params& p) {
  std::string out = "# erodem configuration, fully resolved (values in SI units)\n";
  std::string section = "-";
  const Descriptor* inflow = nullptr;
  for (const Descriptor& d : descriptor_table()) {
    if (d.type == "inflow list") {
      inflow = &d;
      continue;
    }
    const std::string s = section_of(d.key);
    if (s != section) {
      out += "\n[" + s + "]\n";
      section = s;
    }
    out += "# " + d.doc + "\n";
    const std::optional<std::string> value = d.format(p);
    if (value) {
      out += leaf_of(d.key) + " = " + *value + "\n";
    } else {
      out += "# " + leaf_of(d.key) + " = (not set)\n";
    }
  }
  if (inflow) out += format_inflow_tables(p.inflow, inflow->doc);
  return out;
}

std::vector<std::string> parameter_keys() {
  std::vector<std::string> keys;
  for (const Descriptor& d : descriptor_table()) keys.push_back(d.key);
  return keys;
}

std::string parameter_doc(const std::string& key) {
  return require_descriptor(key, "config").doc;
}

ParameterInfo parameter_info(const std::string& key) {
  const Descriptor& d = require_descriptor(key, "config");
  ParameterInfo info;
  info.key = d.key;
  info.type = d.type;
  info.dimension = d.dim;
  info.unit = d.dim == Dimension::dimensionless ? "" : si_unit(d.dim);
  info.accepted = d.accepted;
  const Params defaults;
  if (d.type == "inflow list") {
    info.default_value = "[]";
  } else {
    info.default_value = d.format(defaults).value_or("(not set)");
  }
  info.doc = d.doc;
  return info;
}

std::string closest_parameter_key(const std::string& key) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  const std::string leaf = leaf_of(key);
  for (const Descriptor& d : descriptor_table()) {
    // the same leaf in another section ("dt" -> "time.dt") ranks before any typo
    const size_t distance = leaf_of(d.key) == leaf ? 0 : edit_distance(key, d.key);
    if (distance < best_distance) {
      best_distance = distance;
      best = d.key;
    }
  }
  const size_t limit = std::max<size_t>(2, key.size() / 4);
  return best_distance <= limit ? best : std::string();
}

bool params_equal(const Params& a, const Params& b) {
  return dump_toml(a) == dump_toml(b);
}

}  // namespace erodem
