// erodem viewer — colour maps (colormap.hpp).
#include "erodem/viz/colormap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "erodem/error.hpp"

namespace erodem::viz {

const std::vector<ColorStop>& color_stops(ColorMap map) {
  static const std::vector<ColorStop> terrain{{0.00, {0.18, 0.42, 0.22}},
                                              {0.25, {0.45, 0.62, 0.30}},
                                              {0.50, {0.78, 0.72, 0.45}},
                                              {0.75, {0.55, 0.40, 0.28}},
                                              {1.00, {0.97, 0.97, 0.97}}};
  static const std::vector<ColorStop> water{{0.0, {0.90, 0.88, 0.80}},
                                            {0.15, {0.62, 0.80, 0.90}},
                                            {0.5, {0.30, 0.55, 0.88}},
                                            {1.0, {0.03, 0.15, 0.50}}};
  static const std::vector<ColorStop> sediment{
      {0.0, {0.90, 0.90, 0.86}}, {0.5, {0.85, 0.60, 0.25}}, {1.0, {0.40, 0.20, 0.05}}};
  static const std::vector<ColorStop> speed{{0.00, {0.05, 0.02, 0.20}},
                                            {0.35, {0.55, 0.10, 0.45}},
                                            {0.65, {0.95, 0.35, 0.15}},
                                            {1.00, {0.99, 0.95, 0.45}}};
  // Purple (deposition) - white - orange-brown (erosion): no blue, so that the water drawn
  // over it (blue, scene.cpp) is not taken for deposition.
  static const std::vector<ColorStop> diverging{{0.00, {0.30, 0.12, 0.48}},
                                                {0.25, {0.66, 0.56, 0.80}},
                                                {0.50, {0.97, 0.97, 0.97}},
                                                {0.75, {0.96, 0.66, 0.30}},
                                                {1.00, {0.55, 0.25, 0.02}}};
  // grass, mud, rock, snow, water (codes 0..4 of TerrainClass).
  static const std::vector<ColorStop> classes{{0.0, {0.40, 0.65, 0.25}},
                                              {0.25, {0.45, 0.33, 0.20}},
                                              {0.5, {0.55, 0.55, 0.55}},
                                              {0.75, {0.98, 0.98, 1.00}},
                                              {1.0, {0.20, 0.45, 0.85}}};
  switch (map) {
    case ColorMap::water:
      return water;
    case ColorMap::sediment:
      return sediment;
    case ColorMap::speed:
      return speed;
    case ColorMap::diverging:
      return diverging;
    case ColorMap::classes:
      return classes;
    case ColorMap::terrain:
      break;
  }
  return terrain;
}

const std::vector<std::string>& color_map_names() {
  static const std::vector<std::string> names{"terrain", "water",     "sediment",
                                              "speed",   "diverging", "classes"};
  return names;
}

const std::string& color_map_name(ColorMap map) {
  return color_map_names().at(static_cast<std::size_t>(map));
}

ColorMap color_map_by_name(const std::string& name) {
  const auto& names = color_map_names();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<ColorMap>(k);
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw Error(ExitCode::usage, "--cmap: no colour map '" + name + "' (available: " + list + ")");
}

std::array<double, 3> color_at(ColorMap map, double t) {
  const auto& s = color_stops(map);
  t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
  if (map == ColorMap::classes) {
    const auto k = static_cast<std::size_t>(std::lround(t * (s.size() - 1)));
    return s[k].rgb;
  }
  for (std::size_t k = 1; k < s.size(); ++k)
    if (t <= s[k].t) {
      const double w = (t - s[k - 1].t) / (s[k].t - s[k - 1].t);
      std::array<double, 3> c{};
      for (int i = 0; i < 3; ++i) c[i] = (1 - w) * s[k - 1].rgb[i] + w * s[k].rgb[i];
      return c;
    }
  return s.back().rgb;
}

namespace {

/// The q-quantile (q in [0, 1]) of `v` (reordered); v must not be empty.
double quantile(std::vector<double>& v, double q) {
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

std::optional<std::array<double, 2>> data_color_range(ColorMap map,
                                                      const std::vector<float>& values) {
  if (map == ColorMap::classes) return std::array<double, 2>{0.0, 4.0};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float v : values)
    if (std::isfinite(v)) {
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
    }
  if (!(lo <= hi)) return std::nullopt;  // no finite value
  if (map == ColorMap::diverging) {
    std::vector<double> mag;
    for (float v : values)
      if (std::isfinite(v) && v != 0.0f) mag.push_back(std::abs(static_cast<double>(v)));
    const double m = mag.empty() ? 0.0 : quantile(mag, kDivergingQuantile);
    if (!(m > 0.0)) return std::nullopt;
    return std::array<double, 2>{-m, m};
  }
  if (map != ColorMap::terrain) {
    std::vector<double> v;
    for (float x : values)
      if (std::isfinite(x)) v.push_back(x);
    hi = quantile(v, kColorQuantile);
  }
  if (!(hi > lo)) return std::nullopt;
  return std::array<double, 2>{lo, hi};
}

std::array<double, 2> color_range(ColorMap map, const std::vector<float>& values) {
  if (auto r = data_color_range(map, values)) return *r;
  double lo = std::numeric_limits<double>::infinity();
  for (float v : values)
    if (std::isfinite(v)) lo = std::min(lo, static_cast<double>(v));
  // no finite value, or an all-zero diverging field
  if (!std::isfinite(lo) || map == ColorMap::diverging) return {-1.0, 1.0};
  return {lo, lo + 1.0};  // constant
}

}  // namespace erodem::viz
