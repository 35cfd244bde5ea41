// erodem — physical quantities in configuration values.
// A quantity is a number already in SI units, or a string "<number> <unit>" such as
// "20 mm/h", "6 h", "160 m" or "35 deg". Every parameter has one Dimension; a unit of
// another dimension is an error naming the parameter and the accepted units.
#pragma once

#include <optional>
#include <string>

#include "erodem/error.hpp"

namespace erodem {

/// The physical dimension of a parameter, which fixes the units it accepts.
enum class Dimension {
  dimensionless,  ///< plain number (1)
  length,         ///< m, cm, mm, km
  time,           ///< s, min, h, d
  speed,          ///< m/s, mm/h, mm/d, cm/h, m/h, mm/s (rain rates, velocities)
  angle,          ///< deg, degrees, rad (held in degrees)
  inverse_time,   ///< 1/s, 1/min, 1/h, 1/d
  area,           ///< m^2, cm^2, km^2
  acceleration,   ///< m/s^2
  discharge,      ///< m^3/s, l/s
  manning,        ///< Manning n (s m^-1/3); numbers only
  density,        ///< kg/m^3, g/cm^3
  stress,         ///< Pa, kPa, N/m^2 (shear stresses)
  mass_flux,      ///< kg/m^2/s, g/m^2/s (erosion rates)
  viscosity,      ///< m^2/s, mm^2/s (kinematic viscosity)
};

/// A configuration error from `source` (a file name or "--set") about parameter `key`:
/// "<source>: '<key>': <what>", exit code 78.
inline Error config_error_in(const std::string& source, const std::string& key,
                             const std::string& what) {
  return Error(ExitCode::config, source + ": '" + key + "': " + what);
}

/// The SI unit in which values of `dim` are held, e.g. "m/s" ("1" for dimensionless).
std::string si_unit(Dimension dim);

/// A noun for error messages, e.g. "a rate", "a length", "a number".
std::string dimension_noun(Dimension dim);

/// The accepted unit names, comma separated, e.g. "m/s, mm/h, mm/d, cm/h, m/h, mm/s".
std::string accepted_units(Dimension dim);

/// An example quantity string, e.g. "20 mm/h"; empty for dimensions without units.
std::string unit_example(Dimension dim);

/// Parses "<number>" or "<number> <unit>" into SI. On failure returns nullopt and, when
/// `why` is given, stores a reason naming the accepted units.
std::optional<double> try_parse_quantity(const std::string& text, Dimension dim,
                                         std::string* why = nullptr);

/// Parses a quantity like try_parse_quantity, throwing config_error_in(source, key, ...)
/// on failure.
double parse_quantity(const std::string& text, Dimension dim, const std::string& key,
                      const std::string& source);

/// True when `text` is a number, optionally followed by a unit of any dimension, or by a
/// space or a decimal comma and anything (a quantity with a wrong unit): meant as a quantity,
/// not as a file path ("30m.tif" and "0.5.tif" stay paths).
bool looks_like_quantity(const std::string& text);

/// Formats a number so that it parses back to the same double, in TOML float syntax
/// (always with a '.' or exponent, e.g. "0.05", "1000.0", "1e-06").
std::string format_number(double value);

/// Formats an SI value of `dim` for dumping: the plain SI number (format_number).
std::string format_quantity(double value_si, Dimension dim);

}  // namespace erodem
