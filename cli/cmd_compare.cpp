// `erodem compare A B`: per field, the relative L2 and the largest absolute difference
// between two run outputs at their matching snapshot times; exit 1 when a field differs by
// more than the tolerance.
//
// The two sides, their fields at the matching times and the difference of one field at one
// time come from io/compare.hpp; this file holds the options, the choice of the fields to
// compare, the worst values over the times, and the text and JSON reports.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/compare.hpp"
#include "json.hpp"

namespace erodem::cli {

namespace {

struct CompareOptions {
  std::string a, b;
  double tol = 1e-5;
  bool json = false;
  std::string fields;
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// One field over all matching times: the worst relative L2 and the largest difference.
struct FieldResult {
  std::string field;
  std::size_t times = 0;           ///< snapshot times compared
  std::size_t cells = 0;           ///< cells valid in both (at the last time)
  std::size_t valid_mismatch = 0;  ///< the most at any time
  double rel_l2 = 0.0;             ///< the largest at any time
  double rel_l2_time = std::nan("");
  double max_abs = 0.0;  ///< the largest at any time
  double max_abs_time = std::nan("");
  int max_col = -1, max_row = -1;
  bool ok = true;
};

std::string json_time(double t) {
  return json_number(t);
}

int compare(const CompareOptions& o) {
  if (!(o.tol >= 0)) throw Error(ExitCode::usage, "--tol: expected a number >= 0");
  const auto wanted = split_list(o.fields);
  for (const auto& f : wanted) {
    try {
      field_info(f);
    } catch (const Error& e) {  // names the accepted fields
      throw Error(ExitCode::usage, std::string("--fields: ") + e.what());
    }
  }
  const io::CompareInput a = io::open_compare_input(o.a), b = io::open_compare_input(o.b);
  // The fields to compare, each named as A and B hold it ("" for an unnamed GeoTIFF).
  struct Pair {
    std::string label, in_a, in_b;
  };
  std::vector<Pair> pairs;
  if (a.single && b.single) {
    const std::string name = !wanted.empty()                   ? wanted.front()
                             : !a.files.begin()->first.empty() ? a.files.begin()->first
                             : !b.files.begin()->first.empty() ? b.files.begin()->first
                                                               : "band 1";
    pairs.push_back({name, a.files.begin()->first, b.files.begin()->first});
  } else if (a.single || b.single) {
    const io::CompareInput& one = a.single ? a : b;
    const io::CompareInput& other = a.single ? b : a;
    const std::string name = !wanted.empty() ? wanted.front() : one.files.begin()->first;
    if (name.empty())
      throw Error(
          ExitCode::usage,
          fmt::format("{}: cannot tell which field it holds; name it with --fields", one.path));
    if (!other.has(name)) throw Error(ExitCode::no_input, other.missing(name));
    pairs.push_back(
        {name, a.single ? a.files.begin()->first : name, b.single ? b.files.begin()->first : name});
  } else {
    std::vector<std::string> names = wanted;
    if (names.empty()) {
      const auto fa = a.fields(), fb = b.fields();
      names = fa;
      for (const auto& f : fb)
        if (std::find(names.begin(), names.end(), f) == names.end()) names.push_back(f);
    }
    for (const auto& name : names) {
      for (const io::CompareInput* side : {&a, &b})
        if (!side->has(name))
          throw Error(ExitCode::no_input,
                      side->missing(name) +
                          (wanted.empty() ? " (choose the fields to compare with --fields)" : ""));
      pairs.push_back({name, name, name});
    }
  }
  const auto times = io::matching_times(a, b);
  if (a.h5 && b.h5 &&
      (times.size() != a.h5->times().size() || times.size() != b.h5->times().size()))
    std::fprintf(stderr,
                 "erodem: note: compared the %zu snapshot times both hold (A has %zu, B %zu)\n",
                 times.size(), a.h5->times().size(), b.h5->times().size());

  std::vector<FieldResult> results;
  int nx = 0, ny = 0;
  for (const auto& pair : pairs) {
    FieldResult r;
    r.field = pair.label;
    for (const auto& t : times) {
      const io::RasterBand ra = io::load_compare_field(a, pair.in_a, t.ia),
                           rb = io::load_compare_field(b, pair.in_b, t.ib);
      io::check_same_grid(ra, rb);
      nx = ra.nx;
      ny = ra.ny;
      const io::FieldDifference d = io::field_difference(ra.values, rb.values, ra.nx);
      ++r.times;
      r.cells = d.cells;
      r.valid_mismatch = std::max(r.valid_mismatch, d.valid_mismatch);
      if (d.rel_l2 > r.rel_l2 || r.times == 1) {
        r.rel_l2 = d.rel_l2;
        r.rel_l2_time = t.time;
      }
      if (d.max_abs > r.max_abs) {
        r.max_abs = d.max_abs;
        r.max_abs_time = t.time;
        r.max_col = d.max_col;
        r.max_row = d.max_row;
      }
    }
    r.ok = r.rel_l2 <= o.tol && r.valid_mismatch == 0;
    results.push_back(r);
  }
  const auto failed = static_cast<std::size_t>(
      std::count_if(results.begin(), results.end(), [](const FieldResult& r) { return !r.ok; }));
  std::vector<double> time_list;
  for (const auto& t : times)
    if (!std::isnan(t.time)) time_list.push_back(t.time);

  if (o.json) {
    std::string tl;
    for (double t : time_list) tl += (tl.empty() ? "" : ", ") + json_time(t);
    std::printf(
        "{\"a\": %s, \"b\": %s, \"tol\": %s, \"grid\": [%d, %d], \"times\": [%s], "
        "\"fields\": [",
        json_string(o.a).c_str(), json_string(o.b).c_str(), json_number(o.tol).c_str(), nx, ny,
        tl.c_str());
    for (std::size_t k = 0; k < results.size(); ++k) {
      const auto& r = results[k];
      std::printf(
          "%s\n  {\"field\": %s, \"times\": %zu, \"cells\": %zu, \"valid_mismatch\": %zu, "
          "\"rel_l2\": %s, \"rel_l2_time\": %s, \"max_abs\": %s, \"max_abs_at\": %s, "
          "\"max_abs_time\": %s, \"ok\": %s}",
          k == 0 ? "" : ",", json_string(r.field).c_str(), r.times, r.cells, r.valid_mismatch,
          json_number(r.rel_l2).c_str(), json_time(r.rel_l2_time).c_str(),
          json_number(r.max_abs).c_str(),
          r.max_col < 0 ? "null" : fmt::format("[{}, {}]", r.max_col, r.max_row).c_str(),
          json_time(r.max_abs_time).c_str(), r.ok ? "true" : "false");
    }
    std::printf("\n ], \"failed\": %zu, \"ok\": %s}\n", failed, failed == 0 ? "true" : "false");
  } else {
    std::printf("A: %s\nB: %s\ngrid %d x %d, tolerance %g on ||A - B|| / ||B||, ", o.a.c_str(),
                o.b.c_str(), nx, ny, o.tol);
    if (time_list.empty())
      std::printf("one state (GeoTIFF)\n");
    else if (time_list.size() == 1)
      std::printf("at t = %g s\n", time_list.front());
    else
      std::printf("at %zu times, t = %g .. %g s (worst time shown)\n", time_list.size(),
                  time_list.front(), time_list.back());
    std::printf("%-14s %10s %12s %12s %14s %10s %8s  %s\n", "field", "cells", "rel_L2", "max_abs",
                "at (col,row)", "at t (s)", "nodata", "result");
    for (const auto& r : results) {
      const std::string at = r.max_col < 0 ? "-" : fmt::format("({},{})", r.max_col, r.max_row);
      const std::string when =
          r.max_col < 0 || std::isnan(r.max_abs_time) ? "-" : fmt::format("{:g}", r.max_abs_time);
      std::printf("%-14s %10zu %12.4e %12.4e %14s %10s %8zu  %s\n", r.field.c_str(), r.cells,
                  r.rel_l2, r.max_abs, at.c_str(), when.c_str(), r.valid_mismatch,
                  r.ok                    ? "ok"
                  : r.valid_mismatch != 0 ? "FAIL (nodata differs)"
                                          : "FAIL");
    }
    if (failed == 0)
      std::printf(results.size() == 1 ? "the field is within tolerance\n"
                                      : "all %zu fields within tolerance\n",
                  results.size());
    else
      std::printf("%zu of %zu field%s %s the tolerance\n", failed, results.size(),
                  results.size() == 1 ? "" : "s", failed == 1 ? "fails" : "fail");
  }
  return failed == 0 ? 0 : static_cast<int>(ExitCode::check_failed);
}

}  // namespace

Action add_compare(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* sub = app.add_subcommand(
      "compare", "Relative L2 and max abs difference per field between two run outputs");
  sub->add_option("A", o->a, "Result file (.h5), GeoTIFF fields of a run, or a GeoTIFF")
      ->required();
  sub->add_option("B", o->b, "The reference, in the same forms")->required();
  sub->add_option("--tol", o->tol, "Largest relative L2 difference that passes");
  sub->add_option("--fields", o->fields, "Comma-separated fields to compare (default: all)");
  sub->add_flag("--json", o->json, "Machine-readable output");
  return [o] { return compare(*o); };
}

}  // namespace erodem::cli
