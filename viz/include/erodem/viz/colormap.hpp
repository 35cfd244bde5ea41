// erodem viewer — colour maps and colour ranges of the fields.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace erodem::viz {

/// The colour maps of the viewer.
enum class ColorMap {
  terrain,    ///< bed elevation: green lowlands, brown hills, white peaks
  water,      ///< water depth: dry sand, light blue, deep blue
  sediment,   ///< suspended sediment: pale grey to dark brown
  speed,      ///< flow speed: black-body (dark purple, red, yellow)
  diverging,  ///< erosion / deposition: purple (negative) - white (0) - orange-brown (positive)
  classes,    ///< terrain classes: grass, mud, rock, snow, water (categorical)
};

/// A control point: position t in [0, 1] along the map, and an RGB colour in [0, 1].
struct ColorStop {
  double t;
  std::array<double, 3> rgb;
};

/// The maps' names, in enum order ("terrain", "water", "sediment", "speed", "diverging",
/// "classes"): the values of `erodem view --cmap`.
const std::vector<std::string>& color_map_names();
/// The name of `map`.
const std::string& color_map_name(ColorMap map);
/// The map named `name`; Error(usage) listing the names when there is none.
ColorMap color_map_by_name(const std::string& name);

/// The control points of `map` (for `classes`: one per class, by code).
const std::vector<ColorStop>& color_stops(ColorMap map);
/// The colour at t in [0, 1] (clamped), linearly interpolated between the stops; for
/// `classes`, t is the class code / 3.
std::array<double, 3> color_at(ColorMap map, double t);

/// Values beyond this quantile saturate the `water`, `sediment` and `speed` maps, so that
/// a few extreme cells do not wash out the rest (1).
constexpr double kColorQuantile = 0.99;
/// The `diverging` map's range is +-(this quantile of |v| over the non-zero values): lower
/// than kColorQuantile because erosion is heavy-tailed; see docs/viewer.md for the
/// distribution measured on the Puget Sound run (1).
constexpr double kDivergingQuantile = 0.90;

/// The colour range [lo, hi] of `values` (finite ones; NaN = nodata) under `map`:
/// - `terrain`: the minimum and maximum;
/// - `water`, `sediment`, `speed`: the minimum and the kColorQuantile quantile;
/// - `diverging`: centred on zero, (-m, m) with m the kDivergingQuantile quantile of |v|
///   over the non-zero values;
/// - `classes`: [0, 3].
/// A constant field gets [v, v + 1] (so v takes the map's first colour), an all-nodata or
/// all-zero diverging one [-1, 1]: the range never collapses.
std::array<double, 2> color_range(ColorMap map, const std::vector<float>& values);
/// color_range, or nullopt where it would fall back (no finite value, a constant field, an
/// all-zero diverging one).
std::optional<std::array<double, 2>> data_color_range(ColorMap map,
                                                      const std::vector<float>& values);

}  // namespace erodem::viz
