// erodem — rasters in time (rain.grids, snow.temperature_grids): bands of grid values at known
// times, linear in time between neighbouring bands, held at the ends; the one interpolation of
// every gridded forcing (docs/model.md section 3.2).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace erodem {

/// When the bands lie in time: band k at times[k] (s, increasing), or, where times is empty,
/// at start + k interval (s).
struct BandTimes {
  double start = 0.0;
  double interval = 1.0;
  std::vector<double> times;
};

/// Bands of grid values (one value per DEM cell, row-major) in time: at time t the values are
/// (1 - w) band k + w band k + 1 for the band k and weight w of at(t).
class BandSeries {
 public:
  BandSeries() = default;
  /// `key` names the config key in errors: Error(config) when `times` is given and its count
  /// differs from the bands' or it does not increase, or the bands differ in size.
  BandSeries(std::vector<std::vector<double>> bands, BandTimes times, const std::string& key);

  bool empty() const { return bands_.empty(); }
  std::size_t size() const { return bands_.size(); }
  const std::vector<double>& band(std::size_t k) const { return bands_[k]; }

  /// The band k and weight w of time t (s): w in [0, 1), w = 0 at and outside the ends (band 0
  /// before the first time, the last band after the last).
  std::pair<std::size_t, double> at(double t) const;
  /// The values of time t when its band and weight differ from those of the last call (the
  /// first call always gives them); nullopt when they are the same.
  std::optional<std::vector<double>> values_if_changed(double t);

 private:
  std::vector<std::vector<double>> bands_;
  BandTimes times_;
  std::size_t band_now_ = static_cast<std::size_t>(-1);
  double weight_now_ = -1.0;
};

}  // namespace erodem
