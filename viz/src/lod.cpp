// erodem viewer — block decimation (lod.hpp).
#include "erodem/viz/lod.hpp"

#include <algorithm>
#include <cmath>

namespace erodem::viz {

namespace {

int blocks(int n, int factor) {
  return (n + factor - 1) / factor;
}

}  // namespace

Lod Lod::for_budget(int nx, int ny, std::size_t max_cells) {
  Lod lod;
  lod.nx = nx;
  lod.ny = ny;
  const std::size_t budget = std::max<std::size_t>(max_cells, 1);
  // Start from the square-root estimate and step up until the budget holds.
  const double cells = static_cast<double>(nx) * static_cast<double>(ny);
  int f = std::max(1, static_cast<int>(std::floor(std::sqrt(cells / static_cast<double>(budget)))));
  while (static_cast<std::size_t>(blocks(nx, f)) * static_cast<std::size_t>(blocks(ny, f)) > budget)
    ++f;
  lod.factor = f;
  lod.coarse_nx = blocks(nx, f);
  lod.coarse_ny = blocks(ny, f);
  return lod;
}

double Lod::fine_col(int i) const {
  const int first = i * factor, last = std::min(nx, (i + 1) * factor) - 1;
  return 0.5 * (first + last);
}

double Lod::fine_row(int j) const {
  const int first = j * factor, last = std::min(ny, (j + 1) * factor) - 1;
  return 0.5 * (first + last);
}

std::vector<float> decimate(const std::vector<float>& values, const Lod& lod, Reduce reduce) {
  if (lod.factor == 1) return values;
  std::vector<float> out(lod.coarse_cells());
  const int f = lod.factor;
  for (int j = 0; j < lod.coarse_ny; ++j) {
    const int r0 = j * f, r1 = std::min(lod.ny, r0 + f);
    for (int i = 0; i < lod.coarse_nx; ++i) {
      const int c0 = i * f, c1 = std::min(lod.nx, c0 + f);
      float v;
      if (reduce == Reduce::sample) {
        const std::size_t r = static_cast<std::size_t>((r0 + r1 - 1) / 2);
        v = values[r * static_cast<std::size_t>(lod.nx) +
                   static_cast<std::size_t>((c0 + c1 - 1) / 2)];
      } else {
        double sum = 0.0;
        int n = 0;
        for (int r = r0; r < r1; ++r) {
          const float* row = values.data() + static_cast<std::size_t>(r) * lod.nx;
          for (int c = c0; c < c1; ++c)
            if (std::isfinite(row[c])) {
              sum += row[c];
              ++n;
            }
        }
        v = n ? static_cast<float>(sum / n) : NAN;
      }
      out[static_cast<std::size_t>(j) * lod.coarse_nx + i] = v;
    }
  }
  return out;
}

}  // namespace erodem::viz
