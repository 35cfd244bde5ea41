// erodem — rasters in time (band_series.hpp).
#include "erodem/band_series.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "erodem/error.hpp"

namespace erodem {

BandSeries::BandSeries(std::vector<std::vector<double>> bands, BandTimes times,
                       const std::string& key)
    : bands_(std::move(bands)), times_(std::move(times)) {
  if (!times_.times.empty() && times_.times.size() != bands_.size())
    throw config_error(
        key, fmt::format("{} band times for {} bands", times_.times.size(), bands_.size()));
  for (std::size_t k = 1; k < times_.times.size(); ++k)
    if (!(times_.times[k] > times_.times[k - 1]))
      throw config_error(key, fmt::format("band times do not increase: band {} at {:.10g} s "
                                          "after band {} at {:.10g} s",
                                          k + 1, times_.times[k], k, times_.times[k - 1]));
  for (const auto& b : bands_)
    if (b.size() != bands_.front().size()) throw config_error(key, "the bands differ in size");
  if (times_.times.empty() && !(times_.interval > 0))
    throw config_error(key, "the time between bands is not positive");
}

std::pair<std::size_t, double> BandSeries::at(double t) const {
  const std::size_t last = bands_.size() - 1;
  const auto& times = times_.times;
  if (times.empty()) {  // regular: band k at start + k interval
    const double s = (t - times_.start) / times_.interval;
    if (!(s > 0)) return {0, 0.0};
    if (s >= static_cast<double>(last)) return {last, 0.0};
    const auto k = static_cast<std::size_t>(s);
    return {k, s - static_cast<double>(k)};
  }
  if (!(t > times.front())) return {0, 0.0};
  if (t >= times.back()) return {last, 0.0};
  // the last band at or before t (t < times.back(): k < last)
  const auto k =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  return {k, (t - times[k]) / (times[k + 1] - times[k])};
}

std::optional<std::vector<double>> BandSeries::values_if_changed(double t) {
  const auto [k, w] = at(t);
  if (k == band_now_ && w == weight_now_) return std::nullopt;
  std::vector<double> v = bands_[k];
  if (w > 0)
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = (1 - w) * v[i] + w * bands_[k + 1][i];
  band_now_ = k;
  weight_now_ = w;
  return v;
}

}  // namespace erodem
