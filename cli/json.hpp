// erodem command line — the few helpers the `--json` outputs need (no JSON library).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "erodem/schema.hpp"

namespace erodem::cli {

/// `s` as a JSON string literal, quotes included.
inline std::string json_string(const std::string& s) {
  return quoted_string(s);
}

/// `v` as a JSON number with 7 significant digits; `null` when it is NaN or infinite.
inline std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.7g", v);
  return buf;
}

}  // namespace erodem::cli
