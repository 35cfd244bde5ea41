// erodem — seeded, reproducible synthetic terrain. See terrain_synth.hpp.
//
// Bit-reproducibility rules followed in this file: no std:: random distributions, no libm
// transcendental functions (exp, sin, pow, log, ... are not correctly rounded and differ
// between C libraries); only +, -, *, /, sqrt, floor, fabs and ldexp, which IEEE-754 defines
// exactly; and no contraction of a * b + c into a fused multiply-add (which some targets,
// e.g. aarch64, would otherwise do), switched off below for this translation unit.
// Do not build this file with -ffast-math or clang's -ffp-contract=fast (which ignores the
// pragma); the golden digests in tests/test_terrain_raster.cpp catch such a build.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "erodem/terrain_synth.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "erodem/error.hpp"
#include "erodem/parallel.hpp"
#include "erodem/terrain_rows.hpp"

namespace erodem {
namespace {

// ---- random numbers -------------------------------------------------------------------

/// splitmix64 finaliser: a bijective 64-bit mixer.
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// splitmix64 generator (Steele, Lea & Flood 2014).
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() { return mix64(state_ += 0x9E3779B97F4A7C15ULL); }
  /// The generator `k` draws on (the state after k calls to next()).
  SplitMix64 after(std::uint64_t k) const { return SplitMix64(state_ + k * 0x9E3779B97F4A7C15ULL); }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1).
  double symmetric() { return 2.0 * uniform() - 1.0; }

 private:
  std::uint64_t state_;
};

/// Hash of an integer lattice point and a seed.
std::uint64_t hash2(std::int64_t ix, std::int64_t iy, std::uint64_t seed) {
  std::uint64_t h = mix64(seed ^ (static_cast<std::uint64_t>(ix) * 0x9E3779B97F4A7C15ULL));
  return mix64(h ^ (static_cast<std::uint64_t>(iy) * 0xC2B2AE3D27D4EB4FULL));
}

/// exp(x) from basic operations only (range reduction by ln 2 and a degree-13 Taylor
/// polynomial, relative error ~1e-15), so that it is the same on every machine.
double det_exp(double x) {
  if (x < -700.0) return 0.0;
  if (x > 700.0) return std::numeric_limits<double>::infinity();
  const double ln2 = 0.6931471805599453;
  const double k = std::floor(x / ln2 + 0.5);
  const double r = x - k * ln2;  // |r| <= ~0.35
  double p = 1.0;
  for (int i = 13; i >= 1; --i) p = 1.0 + p * r / i;
  return std::ldexp(p, static_cast<int>(k));
}

// ---- Perlin gradient noise ------------------------------------------------------------

double fade(double t) {
  return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}
double lerp(double a, double b, double t) {
  return a + t * (b - a);
}

/// Dot product of one of 8 unit gradients (axes and diagonals) with (dx, dy).
double grad(std::uint64_t h, double dx, double dy) {
  const double k = 0.70710678118654752440;  // 1 / sqrt(2)
  switch (static_cast<unsigned>(h >> 61)) {
    case 0:
      return dx;
    case 1:
      return -dx;
    case 2:
      return dy;
    case 3:
      return -dy;
    case 4:
      return (dx + dy) * k;
    case 5:
      return (dx - dy) * k;
    case 6:
      return (dy - dx) * k;
    default:
      return -(dx + dy) * k;
  }
}

/// 2-D Perlin gradient noise at (x, y) in lattice units; roughly in [-1, 1], 0 at lattice
/// points. The lattice gradients are hashed from the coordinates, so there is no period.
double perlin(double x, double y, std::uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx);
  const auto iy = static_cast<std::int64_t>(fy);
  const double tx = x - fx, ty = y - fy;
  const double n00 = grad(hash2(ix, iy, seed), tx, ty);
  const double n10 = grad(hash2(ix + 1, iy, seed), tx - 1.0, ty);
  const double n01 = grad(hash2(ix, iy + 1, seed), tx, ty - 1.0);
  const double n11 = grad(hash2(ix + 1, iy + 1, seed), tx - 1.0, ty - 1.0);
  const double u = fade(tx), v = fade(ty);
  return lerp(lerp(n00, n10, u), lerp(n01, n11, u), v);
}

/// floor(log2(n)) for n >= 1.
int ilog2(int n) {
  int k = 0;
  while (n > 1) {
    n >>= 1;
    ++k;
  }
  return k;
}

/// A sum of `octaves` Perlin octaves over nx x ny points, lacunarity 2, gain 0.5: octave o
/// is sampled at (ox_o + x(c, r) f_o, oy_o + y(r) f_o) lattice units with f_o = freq0 2^o,
/// its lattice seed and offsets (ox_o, oy_o) in [0, 1024) drawn from SplitMix64(`stream`).
/// `ridged` selects the ridged multifractal ((1 - |n|)^2 signals weighted by the previous
/// octave, after Musgrave) instead of plain fbm. Rows [r0, r1) of the ny (all by default),
/// row-major ((r1 - r0), nx): each point's value is its own, whatever rows are computed.
template <class X, class Y>
std::vector<double> perlin_octaves(int nx, int ny, int octaves, double freq0, std::uint64_t stream,
                                   bool ridged, X x, Y y, int r0 = 0, int r1 = -1) {
  if (r1 < 0) r1 = ny;
  SplitMix64 rng(stream);
  std::vector<double> out(static_cast<std::size_t>(nx) * static_cast<std::size_t>(r1 - r0), 0.0);
  std::vector<double> weight(ridged ? out.size() : 0, 1.0);
  double freq = freq0;
  double amp = 1.0;
  for (int o = 0; o < octaves; ++o) {
    const std::uint64_t oseed = rng.next();
    const double ox = 1024.0 * rng.uniform(), oy = 1024.0 * rng.uniform();
    for (int r = r0; r < r1; ++r) {
      for (int c = 0; c < nx; ++c) {
        const std::size_t i = static_cast<std::size_t>(r - r0) * nx + c;
        const double n = perlin(ox + x(c, r) * freq, oy + y(r) * freq, oseed);
        if (ridged) {
          double s = 1.0 - std::fabs(n);
          s = s * s * weight[i];
          weight[i] = std::min(1.0, std::max(0.0, 2.0 * s));
          out[i] += amp * s;
        } else {
          out[i] += amp * n;
        }
      }
    }
    freq *= 2.0;
    amp *= 0.5;
  }
  return out;
}

/// The terrain generators' octaves, in cells: the first octave with a period of half the
/// larger grid side, the last with a period of about 4 cells.
/// Rows [r0, r1) of them (all by default), row-major.
std::vector<double> octave_noise(int nx, int ny, std::uint64_t seed, bool ridged, int r0 = 0,
                                 int r1 = -1) {
  const int side = std::max(nx, ny);
  return perlin_octaves(
      nx, ny, std::max(1, ilog2(side) - 2), 2.0 / side, seed ^ 0x5DEECE66DULL, ridged,
      [](int c, int) { return c + 0.5; }, [](int r) { return r + 0.5; }, r0, r1);
}

/// Diamond-square midpoint displacement on an n x n grid, n = 2^k + 1 >= max(nx, ny),
/// cropped to the top-left nx x ny cells. Displacements shrink by 0.55 per level
/// (Hurst exponent ~0.86).
std::vector<double> diamond_square(int nx, int ny, std::uint64_t seed) {
  int n = 2;
  while (n + 1 < std::max(nx, ny)) n *= 2;
  const int size = n + 1;
  std::vector<double> h(static_cast<std::size_t>(size) * size, 0.0);
  auto at = [&](int c, int r) -> double& { return h[static_cast<std::size_t>(r) * size + c]; };
  SplitMix64 rng(seed ^ 0x2545F4914F6CDD1DULL);
  at(0, 0) = rng.symmetric();
  at(n, 0) = rng.symmetric();
  at(0, n) = rng.symmetric();
  at(n, n) = rng.symmetric();
  double scale = 1.0;
  for (int step = n; step > 1; step /= 2) {
    const int half = step / 2;
    // Diamond step: centres of squares.
    for (int r = half; r < size; r += step)
      for (int c = half; c < size; c += step)
        at(c, r) = 0.25 * (at(c - half, r - half) + at(c + half, r - half) +
                           at(c - half, r + half) + at(c + half, r + half)) +
                   scale * rng.symmetric();
    // Square step: edge midpoints, averaging the neighbours that exist.
    for (int r = 0; r < size; r += half) {
      for (int c = (r / half) % 2 == 0 ? half : 0; c < size; c += step) {
        double sum = 0.0;
        int count = 0;
        if (c >= half) sum += at(c - half, r), ++count;
        if (c + half < size) sum += at(c + half, r), ++count;
        if (r >= half) sum += at(c, r - half), ++count;
        if (r + half < size) sum += at(c, r + half), ++count;
        at(c, r) = sum / count + scale * rng.symmetric();
      }
    }
    scale *= 0.55;
  }
  std::vector<double> out(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) out[static_cast<std::size_t>(r) * nx + c] = at(c, r);
  return out;
}

/// Rows [r0, r1) of diamond_square(nx, ny, seed), bit for bit, without its whole grid: each
/// level's lattice (the points of spacing h, both coordinates multiples of h) is made only on
/// the rows the finer levels read of it, from the coarser lattice's rows those read, with each
/// point's displacement the draw diamond_square takes for it (SplitMix64 draws by index: the
/// k-th of a level is the generator after the draws of the coarser levels and of the points
/// before it in diamond_square's loops). A level with spacing h holds about
/// ((r1 - r0) / h + 10) (n / h + 1) values: 1.33 (r1 - r0) n in all, the band's share of the
/// grid (an MPI rank's band: io::load_terrain).
std::vector<double> diamond_square_rows(int nx, int ny, std::uint64_t seed, int r0, int r1) {
  int n = 2;
  while (n + 1 < std::max(nx, ny)) n *= 2;
  // The rows [lo, hi] of a lattice (multiples of its spacing h within), each n / h + 1 points.
  struct Lattice {
    int h = 0, lo = 0, hi = -1;
    std::vector<double> v;
    int width(int n) const { return n / h + 1; }
    double& at(int n, int c, int r) {
      return v[static_cast<std::size_t>((r - lo) / h) * width(n) + static_cast<std::size_t>(c / h)];
    }
    void make(int n, int spacing, int first, int last) {
      h = spacing, lo = first, hi = last;
      v.assign(static_cast<std::size_t>((hi - lo) / h + 1) * width(n), 0.0);
    }
  };
  // The rows each level must give, from the finest (h = 1: rows r0 .. r1 - 1) to the coarsest
  // (h = n): a level's diamond points read the coarser lattice h beyond its rows, and the
  // square points of its first and last rows read diamond points h beyond those.
  std::vector<std::pair<int, int>> need;  // need[j]: spacing 2^j
  need.emplace_back(r0, r1 - 1);
  for (int h = 1; h < n; h *= 2) {
    const int s = 2 * h;
    const auto [a, b] = need.back();
    need.emplace_back(std::max(0, (a - s) / s * s), std::min(n, (b + s + s - 1) / s * s));
  }
  const SplitMix64 rng(seed ^ 0x2545F4914F6CDD1DULL);
  const auto draw = [&rng](std::uint64_t k) { return rng.after(k).symmetric(); };
  Lattice coarse, fine;
  coarse.make(n, n, 0, n);  // the corners, draws 0 .. 3
  coarse.at(n, 0, 0) = draw(0);
  coarse.at(n, n, 0) = draw(1);
  coarse.at(n, 0, n) = draw(2);
  coarse.at(n, n, n) = draw(3);
  std::uint64_t base = 4;  // the draws of the coarser levels
  double scale = 1.0;
  for (int step = n, level = static_cast<int>(need.size()) - 2; step > 1; step /= 2, --level) {
    const int half = step / 2;
    const auto per = static_cast<std::uint64_t>(n / step);  // squares a side
    const auto [a, b] = need[static_cast<std::size_t>(level)];
    // this level's lattice, with the diamond rows beside [a, b] that its square points read
    fine.make(n, half, std::max(0, a - half), std::min(n, b + half));
    for (int r = fine.lo; r <= fine.hi; r += half)  // the coarser lattice's points
      if ((r / half) % 2 == 0)
        for (int c = 0; c <= n; c += step) fine.at(n, c, r) = coarse.at(n, c, r);
    // Diamond step: centres of squares (diamond_square's order: row by row, then column).
    for (int r = fine.lo; r <= fine.hi; r += half) {
      if ((r / half) % 2 == 0) continue;
      const std::uint64_t row_k = base + static_cast<std::uint64_t>((r - half) / step) * per;
      for (int c = half; c <= n; c += step)
        fine.at(n, c, r) =
            0.25 * (coarse.at(n, c - half, r - half) + coarse.at(n, c + half, r - half) +
                    coarse.at(n, c - half, r + half) + coarse.at(n, c + half, r + half)) +
            scale * draw(row_k + static_cast<std::uint64_t>((c - half) / step));
    }
    base += per * per;
    // Square step: edge midpoints on the rows [a, b], averaging the neighbours that exist.
    for (int r = a; r <= b; r += half) {
      const auto j = static_cast<std::uint64_t>(r / half);
      const bool even = j % 2 == 0;
      const std::uint64_t row_k = base + (j + 1) / 2 * per + j / 2 * (per + 1);
      for (int c = even ? half : 0; c <= n; c += step) {
        double sum = 0.0;
        int count = 0;
        if (c >= half) sum += fine.at(n, c - half, r), ++count;
        if (c + half <= n) sum += fine.at(n, c + half, r), ++count;
        if (r >= half) sum += fine.at(n, c, r - half), ++count;
        if (r + half <= n) sum += fine.at(n, c, r + half), ++count;
        fine.at(n, c, r) =
            sum / count +
            scale * draw(row_k + static_cast<std::uint64_t>(even ? (c - half) / step : c / step));
      }
    }
    base += 2 * per * (per + 1);
    scale *= 0.55;
    std::swap(coarse, fine);
  }
  std::vector<double> out(static_cast<std::size_t>(nx) * static_cast<std::size_t>(r1 - r0));
  for (int r = r0; r < r1; ++r)
    for (int c = 0; c < nx; ++c)
      out[static_cast<std::size_t>(r - r0) * nx + c] = coarse.at(n, c, r);
  return out;
}

/// Normalised cell-centre coordinates: u = x / width, v = y / height, both in (0, 1),
/// v growing southwards (row order).
struct Coords {
  int nx, ny;
  double u(int c) const { return (c + 0.5) / nx; }
  double v(int r) const { return (r + 0.5) / ny; }
};

/// The smooth shapes under the fbm of the hill, lake, valley and ridge terrains at cell (c, r)
/// (kShapes, below, gives the fraction of fbm each adds).
double hill_at(const Coords& g, int c, int r) {
  const double sigma = 0.2;  // of the grid extent
  const double du = g.u(c) - 0.5, dv = g.v(r) - 0.5;
  return det_exp(-(du * du + dv * dv) / (2.0 * sigma * sigma));
}

double lake_at(const Coords& g, int c, int r) {
  const double rim = 0.3;  // rim radius, of the grid extent
  const double du = g.u(c) - 0.5, dv = g.v(r) - 0.5;
  const double d = std::sqrt(du * du + dv * dv) / rim;  // 1 on the rim crest
  if (d <= 1.0) return d * d;                           // parabolic bowl, 0 at the centre
  const double t = std::min(1.0, (d - 1.0) / 0.5);      // outer flank, then a plain
  return 1.0 - 0.5 * t * t * (3.0 - 2.0 * t);
}

double valley_at(const Coords& g, int c, int r) {
  const double width = 0.03;  // channel half-width, of the grid height
  const double u = g.u(c);
  const double d = std::fabs(g.v(r) - 0.5) * 2.0;  // 0 on the axis, 1 at the edges
  const double thalweg = 0.5 * (1.0 - u);          // down towards +x (east)
  const double sides = 0.5 * d * std::sqrt(d);     // between a V (d) and a U (d^2)
  const double channel = 0.03 * det_exp(-(d * d) / (width * width));
  return thalweg + sides - channel;
}

double ridge_at(const Coords& g, int c, int r) {
  // Distance from the diagonal u = v, in units of its distance to the far corners.
  const double d = std::fabs(g.u(c) - g.v(r));
  const double t = std::max(0.0, 1.0 - d);
  return t * std::sqrt(t);
}

/// The least and largest of `v`'s rows [o0, o1) of the rows [r0, ...) it holds (nx each),
/// over every process through `reduce`.
std::pair<double, double> rows_range(const std::vector<double>& v, int nx, int r0, int o0, int o1,
                                     const RangeReduce& reduce) {
  const auto first = v.begin() + static_cast<std::ptrdiff_t>(o0 - r0) * nx;
  const auto last = v.begin() + static_cast<std::ptrdiff_t>(o1 - r0) * nx;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  if (first != last) {
    const auto mm = std::minmax_element(first, last);
    lo = *mm.first;
    hi = *mm.second;
  }
  if (reduce) reduce(lo, hi);
  return {lo, hi};
}

/// Maps `h` linearly onto [0, relief], `lo` and `hi` (the whole grid's least and largest value)
/// onto its ends; a constant field becomes 0.
void normalise(std::vector<double>& h, double relief, double lo, double hi) {
  const double range = hi - lo;
  for (double& z : h) {
    z = range > 0.0 ? (z - lo) / range * relief : 0.0;
    z = std::min(relief, std::max(0.0, z));
  }
}

/// The smooth shape of a kind and the fraction of unit fbm (scaled to [-0.5, 0.5]) it adds.
struct Shape {
  SynthKind kind;
  double (*at)(const Coords&, int, int);
  double fraction;
};
constexpr Shape kShapes[] = {{SynthKind::hill, hill_at, 0.05},
                             {SynthKind::lake, lake_at, 0.04},
                             {SynthKind::valley, valley_at, 0.02},
                             {SynthKind::ridge, ridge_at, 0.05}};

}  // namespace

std::vector<double> generate_terrain_rows(SynthKind kind, int nx, int ny, double relief_m,
                                          std::uint64_t seed, int r0, int r1, int o0, int o1,
                                          const RangeReduce& reduce) {
  if (!(0 <= r0 && r0 <= o0 && o0 <= o1 && o1 <= r1 && r1 <= ny))
    throw Error(
        ExitCode::internal,
        fmt::format("synthetic terrain: rows [{}, {}) owning [{}, {}) of {}", r0, r1, o0, o1, ny));
  if (kind == SynthKind::diamond_square) {  // its lattices on the rows these read alone
    std::vector<double> h = diamond_square_rows(nx, ny, seed, r0, r1);
    const auto [lo, hi] = rows_range(h, nx, r0, o0, o1, reduce);
    normalise(h, relief_m, lo, hi);
    return h;
  }
  std::vector<double> h = octave_noise(nx, ny, seed, kind == SynthKind::ridged, r0, r1);
  if (kind != SynthKind::fbm && kind != SynthKind::ridged) {
    // the shape plus its fraction of the fbm, scaled to [-0.5, 0.5] by the whole grid's range
    const Shape* shape = nullptr;
    for (const Shape& k : kShapes)
      if (k.kind == kind) shape = &k;
    if (!shape) throw Error(ExitCode::internal, "synthetic terrain: unknown kind");
    const Coords g{nx, ny};
    const auto [lo, hi] = rows_range(h, nx, r0, o0, o1, reduce);
    const double range = hi - lo;
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < nx; ++c) {
        double& z = h[static_cast<std::size_t>(r - r0) * nx + c];
        const double base = shape->at(g, c, r);
        z = range > 0.0 ? base + shape->fraction * ((z - lo) / range - 0.5) : base;
      }
  }
  // mapped onto [0, relief] by the whole grid's range
  const auto [lo, hi] = rows_range(h, nx, r0, o0, o1, reduce);
  normalise(h, relief_m, lo, hi);
  return h;
}

const std::vector<std::string>& synth_kind_names() {
  static const std::vector<std::string> names{"fbm",  "ridged", "diamond_square", "hill",
                                              "lake", "valley", "ridge"};
  return names;
}

std::string to_string(SynthKind kind) {
  return synth_kind_names().at(static_cast<std::size_t>(kind));
}

SynthKind synth_kind_from_string(const std::string& name) {
  const auto& names = synth_kind_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<SynthKind>(i);
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw Error(ExitCode::usage, "unknown terrain kind '" + name + "'; choose one of: " + list);
}

std::vector<double> generate_terrain(SynthKind kind, int nx, int ny, double cell_size_m,
                                     double relief_m, std::uint64_t seed) {
  if (nx < 1 || ny < 1)
    throw Error(ExitCode::usage, "synthetic terrain: size " + std::to_string(nx) + " x " +
                                     std::to_string(ny) + " must be at least 1 x 1");
  if (static_cast<double>(nx) * ny > 1073741824.0)
    throw Error(ExitCode::usage, "synthetic terrain: size " + std::to_string(nx) + " x " +
                                     std::to_string(ny) + " exceeds 2^30 cells");
  if (!(std::isfinite(cell_size_m) && cell_size_m > 0.0))
    throw Error(ExitCode::usage, "synthetic terrain: cell size must be a positive number of m");
  if (!(std::isfinite(relief_m) && relief_m > 0.0))
    throw Error(ExitCode::usage, "synthetic terrain: relief must be a positive number of m");

  if (kind != SynthKind::diamond_square)
    return generate_terrain_rows(kind, nx, ny, relief_m, seed, 0, ny, 0, ny, nullptr);
  std::vector<double> h = diamond_square(nx, ny, seed);
  const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
  normalise(h, relief_m, *lo, *hi);
  return h;
}

std::vector<double> fbm_field(const Grid& grid, double scale_m, int octaves, std::uint64_t seed) {
  return fbm_rows(grid, scale_m, octaves, seed, 0, grid.ny);
}

std::vector<double> fbm_rows(const Grid& grid, double scale_m, int octaves, std::uint64_t seed,
                             int row0, int row1) {
  grid.validate();
  if (row0 < 0 || row1 > grid.ny || row1 < row0)
    throw Error(ExitCode::internal, "fbm field: rows [" + std::to_string(row0) + ", " +
                                        std::to_string(row1) + ") of a grid of " +
                                        std::to_string(grid.ny));
  if (!(std::isfinite(scale_m) && scale_m > 0.0))
    throw Error(ExitCode::usage, "fbm field: the scale must be a positive length (m)");
  if (octaves < 1 || octaves > 16)
    throw Error(ExitCode::usage,
                "fbm field: between 1 and 16 octaves, got " + std::to_string(octaves));
  // Row centres: the sum of the cell heights of the rows above plus half the row's own.
  std::vector<double> y(static_cast<std::size_t>(grid.ny));
  double top = 0.0, width = 0.0;
  for (int r = 0; r < grid.ny; ++r) {
    y[r] = top + 0.5 * grid.dy[r];
    top += grid.dy[r];
    width = std::max(width, grid.nx * grid.dx[r]);
  }
  // Lattice coordinates must stay far inside the int64 range of perlin()'s lattice indices
  // (and keep a fraction worth sampling): at most 2^40 lattice cells in the last octave.
  if (!(std::max(width, top) / scale_m * std::ldexp(1.0, octaves - 1) <= 0x1.0p40))
    throw Error(ExitCode::usage, "fbm field: a scale of " + std::to_string(scale_m) +
                                     " m is too small for a grid of " + std::to_string(width) +
                                     " x " + std::to_string(top) + " m");
  return perlin_octaves(
      grid.nx, grid.ny, octaves, 1.0 / scale_m, seed ^ 0x6A09E667F3BCC909ULL, false,
      [&](int c, int r) { return (c + 0.5) * grid.dx[r]; }, [&](int r) { return y[r]; }, row0,
      row1);
}

std::vector<double> hardness_noise(const Terrain& terrain, const Params::Erosion& erosion) {
  return hardness_noise_rows(terrain, erosion, 0, terrain.grid.ny);
}

std::vector<double> hardness_noise_rows(const Terrain& terrain, const Params::Erosion& erosion,
                                        int row0, int row1) {
  const double a = erosion.noise_amplitude;
  if (!(std::isfinite(a) && a >= 0.0 && a <= 1.0))
    throw config_error("erosion.noise_amplitude", "must be in [0, 1] (1)");
  if (!(std::isfinite(erosion.noise_scale) && erosion.noise_scale > 0.0))
    throw config_error("erosion.noise_scale", "must be a positive length (m)");
  if (erosion.noise_octaves < 1 || erosion.noise_octaves > 16)
    throw config_error("erosion.noise_octaves",
                       "must be between 1 and 16, got " + std::to_string(erosion.noise_octaves));
  // The seed is an int in the configuration; its two's-complement bits seed the PRNG.
  const auto seed = static_cast<std::uint64_t>(static_cast<std::int64_t>(erosion.noise_seed));
  // The range of the whole grid's active cells, a block of rows at a time (the rows asked
  // for kept as they pass), so that a band of rows holds no field of the whole grid; on a
  // terrain read by rows (an MPI rank's band) each rank's own rows' range, combined (the
  // smallest and the largest value: the same whatever the split).
  const Grid& g = terrain.grid;
  const parallel::Band own = own_rows(terrain);
  if (row0 < 0 || row1 > g.ny || row1 < row0)
    throw Error(ExitCode::internal, "hardness noise: rows [" + std::to_string(row0) + ", " +
                                        std::to_string(row1) + ") of a grid of " +
                                        std::to_string(g.ny));
  const auto nx = static_cast<std::size_t>(g.nx);
  std::vector<double> r;
  r.reserve(nx * static_cast<std::size_t>(std::max(row1 - row0, 0)));
  constexpr int kBlockRows = 256;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int b0 = 0; b0 < g.ny; b0 += kBlockRows) {
    const int b1 = std::min(g.ny, b0 + kBlockRows);
    const int o0 = std::max(b0, own.row0), o1 = std::min(b1, own.row1);  // own rows in it
    const int k0 = std::max(b0, row0), k1 = std::min(b1, row1);          // rows asked for
    if (o1 <= o0 && k1 <= k0) continue;
    const std::vector<double> block =
        fbm_rows(g, erosion.noise_scale, erosion.noise_octaves, seed, b0, b1);
    for (std::size_t k = static_cast<std::size_t>(std::max(o0 - b0, 0)) * nx;
         k < static_cast<std::size_t>(std::max(o1 - b0, 0)) * nx; ++k) {
      if (!terrain.active(static_cast<std::size_t>(b0) * nx + k)) continue;
      lo = std::min(lo, block[k]);
      hi = std::max(hi, block[k]);
    }
    if (k1 > k0)
      r.insert(r.end(), block.begin() + static_cast<std::ptrdiff_t>(k0 - b0) * g.nx,
               block.begin() + static_cast<std::ptrdiff_t>(k1 - b0) * g.nx);
  }
  if (terrain.banded) {
    lo = -parallel::max_over_ranks(-lo);
    hi = parallel::max_over_ranks(hi);
  }
  const double range = hi - lo;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const std::size_t i = static_cast<std::size_t>(row0) * nx + k;
    const double n = terrain.active(i) && range > 0.0 ? (r[k] - lo) / range : 1.0;
    r[k] = 1.0 - a * (1.0 - std::min(1.0, std::max(0.0, n)));
  }
  return r;
}

Terrain make_synthetic_terrain(const Params::Dem& dem, const SynthRows& rows) {
  SynthKind kind;
  try {
    kind = synth_kind_from_string(dem.synthetic);
  } catch (const Error& e) {
    throw config_error("dem.synthetic", e.what());
  }
  if (dem.size < 1 || dem.size > 32768)
    throw config_error("dem.size",
                       "must be between 1 and 32768 cells, got " + std::to_string(dem.size));
  if (!(std::isfinite(dem.cell_size) && dem.cell_size >= 0.0))
    throw config_error("dem.cell_size", "must be a positive length (m)");
  if (!(std::isfinite(dem.relief) && dem.relief > 0.0))
    throw config_error("dem.relief", "must be a positive length (m)");
  const double cell = dem.cell_size > 0.0 ? dem.cell_size : 10.0;

  Terrain t;
  t.grid = Grid::uniform(dem.size, dem.size, cell);
  // The seed is an int in the configuration; its two's-complement bits seed the PRNG.
  const auto seed = static_cast<std::uint64_t>(static_cast<std::int64_t>(dem.seed));
  if (rows.row1 < 0) {
    t.bed = generate_terrain(kind, dem.size, dem.size, cell, dem.relief, seed);
  } else {
    t.bed = generate_terrain_rows(kind, dem.size, dem.size, dem.relief, seed, rows.row0, rows.row1,
                                  rows.own0, rows.own1, rows.reduce);
    t.row0 = rows.row0;
    t.row1 = rows.row1;
  }
  std::ostringstream src;
  src << "synthetic:" << to_string(kind) << " size=" << dem.size << " seed=" << dem.seed
      << " relief=" << dem.relief << " m cell=" << cell << " m";
  t.source = src.str();
  return t;
}

}  // namespace erodem
