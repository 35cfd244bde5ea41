// erodem tests — the validation report's recorder. The validation cases (the analytical,
// physics and precision tests, and test_validation.cpp) assert their bounds through these
// helpers; when ERODEM_VALIDATION_DIR names a folder, every measured figure is also appended
// to <dir>/records.jsonl as one JSON line (case, target, scheme, quantity, resolution, value,
// observed order, bound, pass, reference), and profiles (numerical against reference) go to
// <dir>/profiles/<case>__<target>__<name>.csv. experiments/validation/run.py runs the test
// binary with that variable set and turns the records into docs/validation.md. With
// ERODEM_VALIDATION_LADDER=full the convergence cases run their longer resolution ladders
// (ctest runs the coarse rungs, with the bounds derived for them).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace erodem::test::validation {

/// The folder the records go to, or empty (not recording).
inline std::string record_dir() {
  const char* d = std::getenv("ERODEM_VALIDATION_DIR");
  return d ? std::string(d) : std::string();
}

/// Whether the report asked for the full resolution ladders (ERODEM_VALIDATION_LADDER=full).
inline bool full_ladder() {
  const char* l = std::getenv("ERODEM_VALIDATION_LADDER");
  return l && std::string(l) == "full";
}

/// What a measured figure is: the case it belongs to (one figure of the report per case), the
/// target (backend_precision), the scheme, the quantity and its resolution (m, or a step in s
/// where the case says so; 0 for none), and the reference it is measured against.
struct Figure {
  std::string case_id, target, scheme, quantity;
  double resolution = 0;
  std::string reference;
};

namespace detail {

inline std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + '"';
}

inline std::string number(std::optional<double> v) {
  if (!v || !std::isfinite(*v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", *v);
  return buf;
}

/// Appends one record; `relation` is "<", ">", "in" (lo < value < hi) or "" (reported only).
inline void write(const Figure& f, double value, std::optional<double> order,
                  const std::string& relation, std::optional<double> lo, std::optional<double> hi,
                  bool pass) {
  const std::string dir = record_dir();
  if (dir.empty()) return;
  std::filesystem::create_directories(dir);
  std::ofstream out(dir + "/records.jsonl", std::ios::app);
  out << "{\"case\": " << quoted(f.case_id) << ", \"target\": " << quoted(f.target)
      << ", \"scheme\": " << quoted(f.scheme) << ", \"quantity\": " << quoted(f.quantity)
      << ", \"resolution\": " << number(f.resolution) << ", \"value\": " << number(value)
      << ", \"order\": " << number(order) << ", \"relation\": " << quoted(relation)
      << ", \"bound\": " << number(lo) << ", \"bound_hi\": " << number(hi)
      << ", \"pass\": " << (pass ? "true" : "false") << ", \"reference\": " << quoted(f.reference)
      << ", \"full_ladder\": " << (full_ladder() ? "true" : "false") << "}\n";
}

}  // namespace detail

/// Records a figure that is reported, not bounded.
inline void report(const Figure& f, double value, std::optional<double> order = std::nullopt) {
  detail::write(f, value, order, "", std::nullopt, std::nullopt, true);
}

/// Records `value` against the bound `value < bound` and asserts it.
inline void expect_below(const Figure& f, double value, double bound,
                         std::optional<double> order = std::nullopt) {
  detail::write(f, value, order, "<", bound, std::nullopt, value < bound);
  EXPECT_LT(value, bound) << f.case_id << " " << f.scheme << ": " << f.quantity;
}

/// Records `value` against the bound `value > bound` and asserts it.
inline void expect_above(const Figure& f, double value, double bound,
                         std::optional<double> order = std::nullopt) {
  detail::write(f, value, order, ">", bound, std::nullopt, value > bound);
  EXPECT_GT(value, bound) << f.case_id << " " << f.scheme << ": " << f.quantity;
}

/// Records `value` against the band lo < value < hi and asserts it.
inline void expect_between(const Figure& f, double value, double lo, double hi) {
  detail::write(f, value, std::nullopt, "in", lo, hi, value > lo && value < hi);
  EXPECT_GT(value, lo) << f.case_id << " " << f.scheme << ": " << f.quantity;
  EXPECT_LT(value, hi) << f.case_id << " " << f.scheme << ": " << f.quantity;
}

/// Writes a profile for the report's figure: a CSV with the header `columns` (the first one
/// the abscissa) and one row per index of the equally long `values`.
inline void profile(const Figure& f, const std::string& name,
                    const std::vector<std::string>& columns,
                    const std::vector<std::vector<double>>& values) {
  const std::string dir = record_dir();
  if (dir.empty() || values.empty()) return;
  std::filesystem::create_directories(dir + "/profiles");
  std::ostringstream path;
  path << dir << "/profiles/" << f.case_id << "__" << f.target << "__" << name << ".csv";
  std::ofstream out(path.str());
  out.precision(9);
  for (std::size_t k = 0; k < columns.size(); ++k) out << (k ? "," : "") << columns[k];
  out << "\n";
  for (std::size_t i = 0; i < values[0].size(); ++i) {
    for (std::size_t k = 0; k < values.size(); ++k) out << (k ? "," : "") << values[k][i];
    out << "\n";
  }
}

}  // namespace erodem::test::validation
