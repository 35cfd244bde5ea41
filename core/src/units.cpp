// erodem — parsing and formatting of quantities with units (see units.hpp).
#include "erodem/units.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace erodem {
namespace {

/// One accepted unit: its name, dimension, and factor to SI.
struct Unit {
  const char* name;
  Dimension dim;
  double to_si;
};

constexpr double kPi = 3.14159265358979323846;

/// The unit table: the only place where unit names and factors are written.
const std::vector<Unit>& unit_table() {
  static const std::vector<Unit> units{
      {"m", Dimension::length, 1.0},
      {"cm", Dimension::length, 0.01},
      {"mm", Dimension::length, 0.001},
      {"km", Dimension::length, 1000.0},
      {"s", Dimension::time, 1.0},
      {"min", Dimension::time, 60.0},
      {"h", Dimension::time, 3600.0},
      {"d", Dimension::time, 86400.0},
      {"m/s", Dimension::speed, 1.0},
      {"mm/h", Dimension::speed, 0.001 / 3600.0},
      {"mm/d", Dimension::speed, 0.001 / 86400.0},
      {"cm/h", Dimension::speed, 0.01 / 3600.0},
      {"m/h", Dimension::speed, 1.0 / 3600.0},
      {"mm/s", Dimension::speed, 0.001},
      {"deg", Dimension::angle, 1.0},
      {"degrees", Dimension::angle, 1.0},
      {"rad", Dimension::angle, 180.0 / kPi},
      {"1/s", Dimension::inverse_time, 1.0},
      {"1/min", Dimension::inverse_time, 1.0 / 60.0},
      {"1/h", Dimension::inverse_time, 1.0 / 3600.0},
      {"1/d", Dimension::inverse_time, 1.0 / 86400.0},
      {"m^2", Dimension::area, 1.0},
      {"cm^2", Dimension::area, 1e-4},
      {"km^2", Dimension::area, 1e6},
      {"m/s^2", Dimension::acceleration, 1.0},
      {"m^3/s", Dimension::discharge, 1.0},
      {"l/s", Dimension::discharge, 0.001},
      {"kg/m^3", Dimension::density, 1.0},
      {"g/cm^3", Dimension::density, 1000.0},
      {"Pa", Dimension::stress, 1.0},
      {"kPa", Dimension::stress, 1000.0},
      {"N/m^2", Dimension::stress, 1.0},
      {"kg/m^2/s", Dimension::mass_flux, 1.0},
      {"g/m^2/s", Dimension::mass_flux, 0.001},
      {"m^2/s", Dimension::viscosity, 1.0},
      {"mm^2/s", Dimension::viscosity, 1e-6},
  };
  return units;
}

/// Finds a unit by exact name; nullptr when unknown.
const Unit* find_unit(const std::string& name) {
  for (const Unit& u : unit_table()) {
    if (name == u.name) return &u;
  }
  return nullptr;
}

std::string trim(const std::string& s) {
  size_t b = 0;
  size_t e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

/// Splits "<number> <unit>" into a finite number and the trimmed unit text. Returns
/// false when the text does not start with a finite decimal number.
bool split_number_unit(const std::string& text, double* number, std::string* unit) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  const char c = t[0];
  if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.')) {
    return false;
  }
  const size_t digits = (c == '+' || c == '-') ? 1 : 0;
  if (t.compare(digits, 2, "0x") == 0 || t.compare(digits, 2, "0X") == 0) {
    return false;  // hexadecimal, which strtod would accept
  }
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || !std::isfinite(v)) return false;
  *number = v;
  *unit = trim(std::string(end));
  return true;
}

}  // namespace

std::string si_unit(Dimension dim) {
  switch (dim) {
    case Dimension::dimensionless:
      return "1";
    case Dimension::length:
      return "m";
    case Dimension::time:
      return "s";
    case Dimension::speed:
      return "m/s";
    case Dimension::angle:
      return "degrees";
    case Dimension::inverse_time:
      return "1/s";
    case Dimension::area:
      return "m^2";
    case Dimension::acceleration:
      return "m/s^2";
    case Dimension::discharge:
      return "m^3/s";
    case Dimension::manning:
      return "s m^-1/3";
    case Dimension::density:
      return "kg/m^3";
    case Dimension::stress:
      return "Pa";
    case Dimension::mass_flux:
      return "kg/m^2/s";
    case Dimension::viscosity:
      return "m^2/s";
  }
  return "1";
}

std::string dimension_noun(Dimension dim) {
  switch (dim) {
    case Dimension::dimensionless:
      return "a number";
    case Dimension::length:
      return "a length";
    case Dimension::time:
      return "a duration";
    case Dimension::speed:
      return "a rate";
    case Dimension::angle:
      return "an angle";
    case Dimension::inverse_time:
      return "a rate constant";
    case Dimension::area:
      return "an area";
    case Dimension::acceleration:
      return "an acceleration";
    case Dimension::discharge:
      return "a discharge";
    case Dimension::manning:
      return "a Manning coefficient";
    case Dimension::density:
      return "a density";
    case Dimension::stress:
      return "a stress";
    case Dimension::mass_flux:
      return "a mass flux";
    case Dimension::viscosity:
      return "a kinematic viscosity";
  }
  return "a number";
}

std::string accepted_units(Dimension dim) {
  std::string out;
  for (const Unit& u : unit_table()) {
    if (u.dim != dim) continue;
    if (!out.empty()) out += ", ";
    out += u.name;
  }
  return out;
}

std::string unit_example(Dimension dim) {
  switch (dim) {
    case Dimension::length:
      return "160 m";
    case Dimension::time:
      return "6 h";
    case Dimension::speed:
      return "20 mm/h";
    case Dimension::angle:
      return "35 deg";
    case Dimension::inverse_time:
      return "0.5 1/h";
    case Dimension::area:
      return "1 m^2";
    case Dimension::acceleration:
      return "9.81 m/s^2";
    case Dimension::discharge:
      return "20 m^3/s";
    case Dimension::density:
      return "1000 kg/m^3";
    case Dimension::stress:
      return "0.5 Pa";
    case Dimension::mass_flux:
      return "1e-4 kg/m^2/s";
    case Dimension::viscosity:
      return "1 mm^2/s";
    case Dimension::dimensionless:
    case Dimension::manning:
      return "";
  }
  return "";
}

std::optional<double> try_parse_quantity(const std::string& text, Dimension dim, std::string* why) {
  double number = 0.0;
  std::string unit;
  if (!split_number_unit(text, &number, &unit)) {
    if (why) {
      const std::string ex = unit_example(dim);
      *why = "'" + text + "' is not a number" +
             (ex.empty() ? std::string() : " or a quantity like \"" + ex + "\"");
    }
    return std::nullopt;
  }
  if (unit.empty()) return number;
  const Unit* u = find_unit(unit);
  if (u == nullptr || u->dim != dim) {
    if (why) {
      const std::string accepted = accepted_units(dim);
      *why = "unit '" + unit + "' is not accepted for " + dimension_noun(dim) + "; " +
             (accepted.empty() ? "give a plain number (" + si_unit(dim) + ")"
                               : "accepted units: " + accepted);
    }
    return std::nullopt;
  }
  return number * u->to_si;
}

double parse_quantity(const std::string& text, Dimension dim, const std::string& key,
                      const std::string& source) {
  std::string why;
  const std::optional<double> v = try_parse_quantity(text, dim, &why);
  if (!v) throw config_error_in(source, key, why);
  return *v;
}

bool looks_like_quantity(const std::string& text) {
  double number = 0.0;
  std::string unit;
  if (!split_number_unit(text, &number, &unit)) return false;
  if (unit.empty() || find_unit(unit) != nullptr) return true;
  // a number, then a space or a decimal comma: a quantity whose unit is wrong ("0.03 s m-1/3",
  // "0,03"), not a file name ("30m.tif", "0.5.tif"); its parse says what is wrong (exit 78)
  const std::string t = trim(text);
  const std::size_t at = t.size() - unit.size();
  return at > 0 && (std::isspace(static_cast<unsigned char>(t[at - 1])) || unit[0] == ',');
}

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::array<char, 64> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), value);
  std::string s(buf.data(), res.ptr);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string format_quantity(double value_si, Dimension /*dim*/) {
  return format_number(value_si);
}

}  // namespace erodem
