// erodem — the descriptor kinds of the parameter schema that are written once for one key
// (schema_kinds.hpp): dem.resample, flow.pipe_length and the [[inflow]] tables.
#include "schema_kinds.hpp"

namespace erodem::schema_detail {

namespace {
/// The default parameters, built once (temporaries of the whole Params in every reset lambda
/// made GCC 12 warn of strings "maybe used uninitialized" in their destructors).
const Params& defaults() {
  static const Params d;
  return d;
}
}  // namespace

Descriptor resample_descriptor(const char* key, const char* doc) {
  auto access = [](auto& p) -> auto& {
    return p.dem;
  };
  Descriptor d = base(key, access, "length or integer", Dimension::length,
                      "a cell size >= 0 (m, or a string like \"320 m\"), or an integer "
                      "factor >= 0; 0 = none",
                      doc);
  d.reset = [](Params& p) {
    p.dem.resample = defaults().dem.resample;
    p.dem.resample_factor = defaults().dem.resample_factor;
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

Descriptor hardness_descriptor(const char* key, const char* doc) {
  auto access = [](auto& p) -> auto& {
    return p.erosion.hardness;
  };
  const Descriptor inner =
      scalar_or_raster(key, access, Dimension::dimensionless, closed(0, 1), doc);
  Descriptor d = inner;
  d.type = "number, raster path or \"noise\"";
  d.accepted = inner.accepted + ", or \"noise\"";
  d.reset = [reset = inner.reset](Params& p) {
    reset(p);
    p.erosion.hardness_noise = defaults().erosion.hardness_noise;
  };
  d.assign = [assign = inner.assign](Params& p, const toml::node& n, const Where& w) {
    const auto s = n.value_exact<std::string>();
    if (s && *s == "noise") {
      p.erosion.hardness = defaults().erosion.hardness;
      p.erosion.hardness_noise = true;
      return;
    }
    if (s && !s->empty() && !looks_like_quantity(*s) &&
        s->find_first_of("./\\") == std::string::npos) {
      throw w.fail("expected a number in [0, 1], a raster path or \"noise\", got " + node_text(n) +
                   " (a raster path names its file with an extension or a directory, e.g. "
                   "\"hardness.tif\" or \"./hardness\")");
    }
    assign(p, n, w);
    p.erosion.hardness_noise = false;
  };
  d.check = [check = inner.check](const Params& p, const Where& w) {
    if (!p.erosion.hardness_noise) check(p, w);
  };
  d.format = [format = inner.format](const Params& p) -> std::optional<std::string> {
    return p.erosion.hardness_noise ? quoted_string("noise") : format(p);
  };
  return d;
}

// ---- inflow -----------------------------------------------------------------------------

std::string format_inflow_tables(const std::vector<InflowSpec>& list, const std::string& doc);

const Range kDischargeRange = at_least(0);
const Range kConcentrationRange = right_open(0, 1);

void check_inflow(const InflowSpec& in, const Where& w) {
  if (in.vertices.empty()) throw w.fail("needs a point = [x, y] or a line = [[x, y], ...]");
  check_points(in.vertices, w.sub(in.vertices.size() == 1 ? ".point" : ".line"));
  if (in.hydrograph.empty()) throw w.sub(".hydrograph").fail("needs at least one [t, Q] pair");
  check_series(in.hydrograph, Dimension::discharge, kDischargeRange, w.sub(".hydrograph"));
  if (!kConcentrationRange.contains(in.sediment_concentration))
    throw w.sub(".sediment_concentration")
        .fail("expected a volume concentration " + kConcentrationRange.text());
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
    } else if (name == "sediment_concentration") {
      in.sediment_concentration = read_double(v, Dimension::dimensionless, kConcentrationRange, wk);
    } else {
      throw wk.fail(
          "unknown inflow key; accepted: point, line, hydrograph, sediment_concentration");
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
                      "hydrograph = [[t, Q], ...] with Q >= 0 (m^3/s), optional "
                      "sediment_concentration in [0, 1) (1, solid volume per water volume)",
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
  d.tables = [doc = d.doc](const Params& p) { return format_inflow_tables(p.inflow, doc); };
  return d;
}

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
    if (in.sediment_concentration != 0.0)
      out += "sediment_concentration = " + format_number(in.sediment_concentration) + "\n";
  }
  return out;
}

// ---- sections and outlets ------------------------------------------------------------

/// A section's or outlet's name: letters, digits, '_' and '-', 1 to 64 characters (a column
/// name in Python, a label in the summary).
std::string read_measure_name(const toml::node& n, const Where& w) {
  const std::string name = read_string(n, w);
  const bool ok = !name.empty() && name.size() <= 64 &&
                  name.find_first_not_of(
                      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                      "0123456789_-") == std::string::npos;
  if (!ok)
    throw w.fail("expected a name of 1 to 64 letters, digits, '_' or '-', got " + node_text(n));
  return name;
}

/// The names of the sections and outlets are one namespace: a repeated one is an error
/// naming its second table.
void check_measure_names(const Params& p, const Where& root) {
  std::vector<std::string> seen;
  auto add = [&](const std::string& name, const std::string& where) {
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw Where{root.source, where}.fail(
          "duplicate section/outlet name \"" + name +
          "\" (names are unique among [[section]] and [[outlet]])");
    seen.push_back(name);
  };
  for (std::size_t i = 0; i < p.section.size(); ++i)
    add(p.section[i].name, "section[" + std::to_string(i) + "].name");
  for (std::size_t i = 0; i < p.outlet.size(); ++i)
    add(p.outlet[i].name, "outlet[" + std::to_string(i) + "].name");
}

void check_section(const SectionSpec& s, const Where& w) {
  if (s.name.empty()) throw w.sub(".name").fail("needs a name = \"...\"");
  if (s.vertices.size() < 2)
    throw w.sub(".line").fail("a section needs a line = [[x, y], ...] of two or more vertices");
  check_points(s.vertices, w.sub(".line"));
}

SectionSpec read_section(const toml::node& n, const Where& w) {
  const toml::table* t = n.as_table();
  if (!t) throw w.fail("expected a table with name and line; got " + node_text(n));
  SectionSpec s;
  for (auto&& [k, v] : *t) {
    const std::string name(k.str());
    const Where wk = w.sub("." + name);
    if (name == "name") {
      s.name = read_measure_name(v, wk);
    } else if (name == "line") {
      s.vertices = read_points(v, wk);
    } else {
      throw wk.fail("unknown section key; accepted: name, line");
    }
  }
  check_section(s, w);
  return s;
}

std::string format_section(const SectionSpec& s) {
  return "name = " + quoted_string(s.name) + "\nline = " + format_points(s.vertices) + "\n";
}

/// An array of named tables ([[section]], [[outlet]]) in Params::*member: each read by
/// `read` and checked by `check` with the key `<key>[i]`, printed by `format` under
/// `[[<key>]]`, and the names checked unique among the sections and outlets.
template <class Spec>
Descriptor named_tables(const char* key, std::vector<Spec> Params::*member, std::string accepted,
                        const char* doc, Spec (*read)(const toml::node&, const Where&),
                        void (*check)(const Spec&, const Where&),
                        std::string (*format)(const Spec&)) {
  auto access = [member](auto& p) -> auto& {
    return p.*member;
  };
  const std::string table = std::string("[[") + key + "]]";
  Descriptor d =
      base(key, access, std::string(key) + " list", Dimension::dimensionless, accepted, doc);
  d.assign = [=](Params& p, const toml::node& n, const Where& w) {
    const toml::array& a =
        read_array(n, "an array of " + std::string(key) + " tables (" + table + ")", w);
    std::vector<Spec> list;
    for (size_t i = 0; i < a.size(); ++i)
      list.push_back(read(*a.get(i), w.sub("[" + std::to_string(i) + "]")));
    p.*member = std::move(list);
  };
  d.check = [=](const Params& p, const Where& w) {
    for (size_t i = 0; i < (p.*member).size(); ++i)
      check((p.*member)[i], w.sub("[" + std::to_string(i) + "]"));
    check_measure_names(p, w);
  };
  d.format = [](const Params&) -> std::optional<std::string> { return std::nullopt; };
  d.tables = [=, doc = d.doc](const Params& p) {
    std::string out = "\n# " + doc + "\n";
    if ((p.*member).empty()) return out + "# (no " + table + " tables)\n";
    for (const Spec& s : p.*member) out += table + "\n" + format(s);
    return out;
  };
  return d;
}

Descriptor section_descriptor(const char* key, const char* doc) {
  return named_tables<SectionSpec>(
      key, &Params::section,
      "[[section]] tables: name = \"...\" (letters, digits, _ and -; unique among sections and "
      "outlets), line = [[x, y], ...] (two or more vertices in the DEM's CRS, inside the grid)",
      doc, read_section, check_section, format_section);
}

const char* const kOutletEdges[] = {"north", "south", "east", "west"};

void check_outlet(const OutletSpec& o, const Where& w) {
  if (o.name.empty()) throw w.sub(".name").fail("needs a name = \"...\"");
  if (o.edge.empty()) {
    check_points({o.point}, w.sub(".point"));
  } else if (std::find(std::begin(kOutletEdges), std::end(kOutletEdges), o.edge) ==
             std::end(kOutletEdges)) {
    throw w.sub(".edge").fail("expected \"north\", \"south\", \"east\" or \"west\", got \"" +
                              o.edge + "\"");
  }
}

OutletSpec read_outlet(const toml::node& n, const Where& w) {
  const toml::table* t = n.as_table();
  if (!t) throw w.fail("expected a table with name, and edge or point; got " + node_text(n));
  OutletSpec o;
  bool has_edge = false, has_point = false;
  for (auto&& [k, v] : *t) {
    const std::string name(k.str());
    const Where wk = w.sub("." + name);
    if (name == "name") {
      o.name = read_measure_name(v, wk);
    } else if (name == "edge") {
      o.edge = read_string(v, wk);
      has_edge = true;
    } else if (name == "point") {
      o.point = read_pair(v, Dimension::dimensionless, any_finite(), Dimension::dimensionless,
                          "an [x, y] point", wk);
      has_point = true;
    } else {
      throw wk.fail("unknown outlet key; accepted: name, edge, point");
    }
  }
  if (has_edge && has_point) throw w.fail("give an edge or a point, not both");
  if (!has_edge && !has_point)
    throw w.fail("needs an edge = \"north\"|\"south\"|\"east\"|\"west\" or a point = [x, y]");
  check_outlet(o, w);
  return o;
}

std::string format_outlet(const OutletSpec& o) {
  return "name = " + quoted_string(o.name) + "\n" +
         (o.edge.empty() ? "point = " + format_pair(o.point[0], o.point[1])
                         : "edge = " + quoted_string(o.edge)) +
         "\n";
}

Descriptor outlet_descriptor(const char* key, const char* doc) {
  return named_tables<OutletSpec>(
      key, &Params::outlet,
      "[[outlet]] tables: name = \"...\" (unique among sections and outlets), and edge = "
      "\"north\"|\"south\"|\"east\"|\"west\" (the whole edge) or point = [x, y] (the faces "
      "the cell under it shares with the outside: the grid's edge or nodata cells)",
      doc, read_outlet, check_outlet, format_outlet);
}

}  // namespace erodem::schema_detail
