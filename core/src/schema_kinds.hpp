// erodem — the descriptor kinds of the parameter schema (private to core/src): a Descriptor
// reads, checks, formats and resets one key of Params; one builder per kind of value (number,
// integer, boolean, string, choice, optional number, number or raster, series, points, names,
// window, and the special keys of schema_kinds.cpp); the table of schema_table.cpp uses them.
#pragma once

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "schema_values.hpp"

namespace erodem::schema_detail {

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
  /// Arrays of tables ([[inflow]], [[section]], [[outlet]]): their dump_toml text (`format`
  /// gives nullopt); null for every other key.
  std::function<std::string(const Params&)> tables;
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

/// true, false, or not set (none: the default the code derives, e.g. from the grid).
template <class Access>
Descriptor optional_boolean(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "optional boolean", Dimension::dimensionless,
                      "true | false, or \"none\"", doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    if (n.value_exact<std::string>() == std::optional<std::string>("none"))
      access(p).reset();
    else
      access(p) = read_bool(n, w);
  };
  d.check = [](const Params&, const Where&) {};
  d.format = [=](const Params& p) -> std::optional<std::string> {
    if (!access(p)) return std::nullopt;
    return std::string(*access(p) ? "true" : "false");
  };
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

/// scalar_or_raster's value, or not set (nullopt; printed as absent).
template <class Access>
Descriptor optional_scalar_or_raster(const char* key, Access access, Dimension dim, Range range,
                                     const char* doc) {
  // the value, made on assignment; read from a const Params (by the checks this descriptor
  // replaces below) an unset one reads as the default
  const auto inner = [access](auto& p) -> auto& {
    if constexpr (std::is_const_v<std::remove_reference_t<decltype(p)>>) {
      static const ScalarOrRaster unset{};
      return access(p) ? *access(p) : unset;
    } else {
      if (!access(p)) access(p).emplace();
      return *access(p);
    }
  };
  Descriptor d = scalar_or_raster(key, inner, dim, range, doc);
  d.type = "optional number or raster path";
  d.check = [=](const Params& p, const Where& w) {
    if (access(p) && !access(p)->is_raster()) check_double(access(p)->value, dim, range, w);
  };
  d.format = [=](const Params& p) -> std::optional<std::string> {
    if (!access(p)) return std::nullopt;
    return access(p)->is_raster() ? quoted_string(access(p)->path)
                                  : format_number(access(p)->value);
  };
  d.reset = [access](Params& p) { access(p).reset(); };
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

/// A list of times [t1, t2, ...] (s, or quantities such as "10 min"), increasing; [] = none.
template <class Access>
Descriptor times(const char* key, Access access, const char* doc) {
  Descriptor d = base(key, access, "times", Dimension::time, "[time, ...], increasing", doc);
  auto check_times = [](const std::vector<double>& v, const Where& w) {
    for (size_t i = 0; i < v.size(); ++i) {
      check_double(v[i], Dimension::time, any_finite(), w.sub("[" + std::to_string(i) + "]"));
      if (i > 0 && !(v[i] > v[i - 1]))
        throw w.fail("times must increase: [" + std::to_string(i) + "] = " + format_number(v[i]) +
                     " s is not after " + format_number(v[i - 1]) + " s");
    }
  };
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    const toml::array& a = read_array(n, "an array of times [t1, t2, ...]", w);
    std::vector<double> v;
    for (size_t i = 0; i < a.size(); ++i)
      v.push_back(read_double(*a.get(i), Dimension::time, any_finite(),
                              w.sub("[" + std::to_string(i) + "]")));
    check_times(v, w);
    access(p) = std::move(v);
  };
  d.check = [=](const Params& p, const Where& w) { check_times(access(p), w); };
  d.format = [=](const Params& p) {
    std::string out = "[";
    for (size_t i = 0; i < access(p).size(); ++i)
      out += (i ? ", " : "") + format_number(access(p)[i]);
    return out + "]";
  };
  return d;
}

/// A number (`value`), or a time series [[t, value], ...] with increasing times (`series`; an
/// empty series means the number): one key for a value constant or varying in time.
template <class Value, class SeriesAccess>
Descriptor number_or_series(const char* key, Value value, SeriesAccess series_of, Dimension dim,
                            Range range, const char* doc) {
  Descriptor d = base(key, value, "number or series", dim,
                      (range.text().empty() ? std::string("number") : range.text()) +
                          ", or [[time, value], ...] with times increasing",
                      doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    if (n.is_array()) {
      Series s = read_series(n, dim, range, w);
      check_series(s, dim, range, w);
      series_of(p) = std::move(s);
    } else {
      value(p) = read_double(n, dim, range, w);
      series_of(p).clear();
    }
  };
  d.check = [=](const Params& p, const Where& w) {
    if (series_of(p).empty())
      check_double(value(p), dim, range, w);
    else
      check_series(series_of(p), dim, range, w);
  };
  d.format = [=](const Params& p) {
    return series_of(p).empty() ? format_number(value(p)) : format_series(series_of(p));
  };
  d.reset = [value, series_of](Params& p) {
    const Params defaults;
    value(p) = value(defaults);
    series_of(p) = series_of(defaults);
  };
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
Descriptor resample_descriptor(const char* key, const char* doc);

/// flow.pipe_length: "cell" (stored as 0) or a length > 0.
Descriptor pipe_length_descriptor(const char* key, const char* doc);

/// erosion.hardness: a number or raster path as scalar_or_raster reads them, or "noise"
/// (Params::Erosion::hardness_noise). A bare word (no '.', '/' or '\\') is neither a raster
/// file name nor "noise", and is rejected, so that a typo such as "nois" fails here.
Descriptor hardness_descriptor(const char* key, const char* doc);

/// [[inflow]]: point or line inflows, each with a hydrograph.
Descriptor inflow_descriptor(const char* key, const char* doc);

/// [[section]]: named cross-section polylines (sections.hpp).
Descriptor section_descriptor(const char* key, const char* doc);

/// [[outlet]]: named outlets, a whole boundary edge or one cell's faces with the outside.
Descriptor outlet_descriptor(const char* key, const char* doc);

/// Every parameter, grouped by section (sections must be contiguous for dump_toml).
const std::vector<Descriptor>& descriptor_table();

}  // namespace erodem::schema_detail
