// A plain two-kernel pipe model (Mei, Decaudin & Hu 2007), the yardstick of issue 20's pipes
// target ("a plain two-kernel pipes prototype reaches 5e8 cell-steps/s on this machine kind").
// It is not erodem: one file, no erodem header, float32, walls on all four sides, OpenMP over
// rows. landlab_compare.py builds it with the system's g++ and runs it beside `erodem bench`
// on the same terrain and scenario, so that the two rates come from the same hour of this VM.
//
// Each step is two sweeps over the interior cells:
//   1. flow: each of a cell's four outflows f <- max(0, f + dt A g (eta - eta_n) / l), the
//      four scaled by K = min(1, d area / (dt sum f)) (what the cell holds);
//   2. water: d <- d + dt (inflows - outflows) / area + dt rain.
// Options add what erodem's step also does every step, so their cost in plain code is
// measured too:
//   --velocities  Mei's velocities, u = (mean discharge through the x faces) / (dy d_mean),
//                 in the water sweep (erodem writes them every step: its per-step max_speed
//                 diagnostic, erosion's capacity);
//   --sums        the step's water volume (a double sum) and largest depth, per row in the
//                 water sweep and then over the rows (erodem's per-step ledger and stability
//                 check).
//
// Usage: pipes_plain ELEVATION.f32 NX NY CELL STEPS [--depth M] [--rain M_PER_S] [--dt S]
//                    [--repeats N] [--velocities] [--sums]
// ELEVATION.f32 holds NX * NY float32 values (m), row by row. Prints one JSON object: the
// median cell-steps/s over the repeats, each repeat's, and the water volume's error against
// the initial volume plus the rain (m^3; walls, so nothing leaves).
// Build with erodem's value-safe kernel flags (without -fno-trapping-math GCC leaves the flow
// loop scalar), all on one line:
//   g++ -std=c++17 -O3 -march=native -fopenmp -fno-math-errno -fno-trapping-math
//       -ffp-contract=off -o pipes_plain pipes_plain.cpp
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace {

struct Scenario {
  int nx = 0, ny = 0;
  float cell = 10.0f;   // m
  float depth = 0.2f;   // initial depth on every cell (m)
  float rain = 0.0f;    // m/s
  float dt = 0.5f;      // s
  float pipe_area = 1;  // m^2 (erodem's flow.pipe_area default)
  float gravity = 9.81f;
  bool velocities = false, sums = false;
};

/// The state on a grid padded by one ghost cell on each side (W = nx + 2, H = ny + 2). The
/// ghosts' bed is 1e30 m, so every pipe into a ghost computes max(0, f - huge) = 0: walls
/// without a mask.
struct State {
  int W = 0, H = 0;
  std::vector<float> bed, depth, f_left, f_right, f_top, f_bottom, u, v;
  std::vector<double> row_volume;
  std::vector<float> row_max;
};

State initial_state(const Scenario& s, const std::vector<float>& elevation) {
  State st;
  st.W = s.nx + 2;
  st.H = s.ny + 2;
  const std::size_t n = static_cast<std::size_t>(st.W) * st.H;
  st.bed.assign(n, 1e30f);
  st.depth.assign(n, 0.0f);
  for (int y = 0; y < s.ny; ++y)
    for (int x = 0; x < s.nx; ++x) {
      const std::size_t i = static_cast<std::size_t>(y + 1) * st.W + x + 1;
      st.bed[i] = elevation[static_cast<std::size_t>(y) * s.nx + x];
      st.depth[i] = s.depth;
    }
  for (auto* f : {&st.f_left, &st.f_right, &st.f_top, &st.f_bottom, &st.u, &st.v})
    f->assign(n, 0.0f);
  st.row_volume.assign(static_cast<std::size_t>(st.H), 0.0);
  st.row_max.assign(static_cast<std::size_t>(st.H), 0.0f);
  return st;
}

/// max(0, p) as a select, as erodem's pipe_outflow writes it.
inline float floor0(float p) {
  return p > 0.0f ? p : 0.0f;
}

/// Sweep 1: the four outflows of every interior cell, in place (each cell reads only its own
/// outflows and its neighbours' surfaces).
void flow(const Scenario& s, State& st) {
  const int W = st.W, H = st.H;
  const float k = s.dt * s.pipe_area * s.gravity / s.cell, area = s.cell * s.cell, dt = s.dt;
  const float* bed = st.bed.data();
  const float* d = st.depth.data();
  float *fl = st.f_left.data(), *fr = st.f_right.data(), *ft = st.f_top.data(),
        *fb = st.f_bottom.data();
#pragma omp parallel for schedule(static)
  for (int y = 1; y < H - 1; ++y) {
#pragma omp simd
    for (int x = 1; x < W - 1; ++x) {
      const int i = y * W + x;
      const float eta = bed[i] + d[i];
      const float gl = floor0(fl[i] + k * (eta - (bed[i - 1] + d[i - 1])));
      const float gr = floor0(fr[i] + k * (eta - (bed[i + 1] + d[i + 1])));
      const float gt = floor0(ft[i] + k * (eta - (bed[i - W] + d[i - W])));
      const float gb = floor0(fb[i] + k * (eta - (bed[i + W] + d[i + W])));
      // a depth a rounding below 0 holds nothing (without the floor, held < 0 gave a negative
      // K, or 0 * -inf = NaN where no pipe carries water)
      const float demand = (gl + gr + gt + gb) * dt, held = floor0(d[i]) * area;
      // the division on a select, not under a branch: a division under a condition keeps the
      // loop from vectorising (GCC will not if-convert what may trap)
      const bool limited = demand > held;
      const float ratio = held / (limited ? demand : 1.0f);
      const float K = limited ? ratio : 1.0f;
      fl[i] = gl * K;
      fr[i] = gr * K;
      ft[i] = gt * K;
      fb[i] = gb * K;
    }
  }
}

/// One row of sweep 2 (below), with or without the velocities and the sums: each variant a
/// loop of its own, so the compiler keeps nothing of the others in it.
template <bool Velocities, bool Sums>
void water_row(const Scenario& s, State& st, int y) {
  const int W = st.W;
  const float dt = s.dt, inv_area = 1.0f / (s.cell * s.cell), rain = s.rain * s.dt;
  const float inv_2w = 0.5f / s.cell;
  const float* fl = st.f_left.data();
  const float* fr = st.f_right.data();
  const float* ft = st.f_top.data();
  const float* fb = st.f_bottom.data();
  float *d = st.depth.data(), *u = st.u.data(), *v = st.v.data();
  double volume = 0.0;
  float deepest = 0.0f;
#pragma omp simd reduction(+ : volume) reduction(max : deepest)
  for (int x = 1; x < W - 1; ++x) {
    const int i = y * W + x;
    const float in = fr[i - 1] + fl[i + 1] + fb[i - W] + ft[i + W];
    const float out = fl[i] + fr[i] + ft[i] + fb[i];
    const float d_old = d[i];
    const float d_new = d_old + dt * (in - out) * inv_area + rain;
    d[i] = d_new;
    if (Velocities) {
      const float mean = 0.5f * (d_old + d_new);
      const float qx = (fr[i - 1] - fl[i]) + (fr[i] - fl[i + 1]);
      const float qy = (ft[i] - fb[i - W]) + (ft[i + W] - fb[i]);
      const float h = mean > 1e-4f ? mean : 1.0f;
      u[i] = mean > 1e-4f ? qx * inv_2w / h : 0.0f;
      v[i] = mean > 1e-4f ? qy * inv_2w / h : 0.0f;
    }
    if (Sums) {
      volume += d_new;
      deepest = std::max(deepest, d_new);
    }
  }
  st.row_volume[static_cast<std::size_t>(y)] = volume;
  st.row_max[static_cast<std::size_t>(y)] = deepest;
}

/// Sweep 2: every interior cell's depth from the outflows in and out and the rain, in place;
/// with the options, its velocities and the row's volume and largest depth.
void water(const Scenario& s, State& st) {
  const int H = st.H;
  const bool velocities = s.velocities, sums = s.sums;
#pragma omp parallel for schedule(static)
  for (int y = 1; y < H - 1; ++y) {
    if (velocities && sums)
      water_row<true, true>(s, st, y);
    else if (velocities)
      water_row<true, false>(s, st, y);
    else if (sums)
      water_row<false, true>(s, st, y);
    else
      water_row<false, false>(s, st, y);
  }
}

/// The step's total volume and largest depth from the rows' (what --sums adds each step).
void reduce_rows(State& st, double& volume, float& deepest) {
  volume = 0.0;
  deepest = 0.0f;
  for (int y = 1; y < st.H - 1; ++y) {
    volume += st.row_volume[static_cast<std::size_t>(y)];
    deepest = std::max(deepest, st.row_max[static_cast<std::size_t>(y)]);
  }
}

double total_volume(const Scenario& s, const State& st) {
  double v = 0.0;
  for (int y = 1; y < st.H - 1; ++y)
    for (int x = 1; x < st.W - 1; ++x) v += st.depth[static_cast<std::size_t>(y) * st.W + x];
  return v * static_cast<double>(s.cell) * s.cell;
}

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "pipes_plain: %s\nusage: pipes_plain ELEVATION.f32 NX NY CELL STEPS [--depth M] "
               "[--rain M_PER_S] [--dt S] [--repeats N] [--velocities] [--sums]\n",
               why);
  std::exit(2);
}

double number(const char* text, const char* name) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v))
    usage((std::string(name) + ": not a number").c_str());
  return v;
}

/// A whole number in [lo, hi], or the usage.
int whole(const char* text, const char* name, long lo, long hi) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < lo || v > hi)
    usage((std::string(name) + ": expected a whole number from " + std::to_string(lo) + " to " +
           std::to_string(hi))
              .c_str());
  return static_cast<int>(v);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) usage("too few arguments");
  Scenario s;
  const std::string path = argv[1];
  s.nx = whole(argv[2], "NX", 3, 46000);  // padded, (NX + 2) (NY + 2) indexes as an int
  s.ny = whole(argv[3], "NY", 3, 46000);
  s.cell = static_cast<float>(number(argv[4], "CELL"));
  const int steps = whole(argv[5], "STEPS", 1, 1000000);
  int repeats = 3;
  for (int a = 6; a < argc; ++a) {
    const std::string o = argv[a];
    const auto value = [&](const char* name) {
      if (a + 1 >= argc) usage((o + ": needs a value").c_str());
      return number(argv[++a], name);
    };
    const auto count = [&](const char* name) {
      if (a + 1 >= argc) usage((o + ": needs a value").c_str());
      return whole(argv[++a], name, 1, 1000);
    };
    if (o == "--depth")
      s.depth = static_cast<float>(value("--depth"));
    else if (o == "--rain")
      s.rain = static_cast<float>(value("--rain"));
    else if (o == "--dt")
      s.dt = static_cast<float>(value("--dt"));
    else if (o == "--repeats")
      repeats = count("--repeats");
    else if (o == "--velocities")
      s.velocities = true;
    else if (o == "--sums")
      s.sums = true;
    else
      usage((o + ": unknown option").c_str());
  }
  if (!(s.cell > 0) || !(s.dt > 0) || !(s.depth >= 0) || !(s.rain >= 0))
    usage("CELL and --dt > 0, --depth and --rain >= 0");
  std::vector<float> elevation(static_cast<std::size_t>(s.nx) * s.ny);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto bytes = static_cast<std::streamoff>(elevation.size() * sizeof(float));
  if (!in || in.tellg() != bytes)
    usage((path + ": expected exactly NX * NY float32 values (" + std::to_string(bytes) + " bytes)")
              .c_str());
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(elevation.data()), bytes))
    usage((path + ": cannot read its NX * NY float32 values").c_str());
  for (const float z : elevation)
    if (!std::isfinite(z)) usage((path + ": an elevation is not a finite number").c_str());

  std::vector<double> rates;
  double volume_error = 0.0, last_volume = 0.0;  // the last step's sums (--sums)
  float last_deepest = 0.0f;
  for (int r = 0; r < repeats; ++r) {
    State st = initial_state(s, elevation);
    const double v0 = total_volume(s, st);
    double volume = 0.0;
    float deepest = 0.0f;
    for (int k = 0; k < 2; ++k) flow(s, st), water(s, st);  // warm: pages touched, caches
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) {
      flow(s, st);
      water(s, st);
      if (s.sums) reduce_rows(st, volume, deepest);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rates.push_back(static_cast<double>(s.nx) * s.ny * steps / seconds);
    const double rain =
        static_cast<double>(s.rain) * s.dt * (steps + 2) * s.nx * s.ny * s.cell * s.cell;
    volume_error = total_volume(s, st) - (v0 + rain);
    last_volume = volume * static_cast<double>(s.cell) * s.cell;
    last_deepest = deepest;
  }
  std::vector<double> sorted = rates;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.size() % 2
                            ? sorted[sorted.size() / 2]
                            : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
  std::printf("{\"cell_steps_per_second\": %.6g, \"repeats\": [", median);
  for (std::size_t k = 0; k < rates.size(); ++k) std::printf("%s%.6g", k ? ", " : "", rates[k]);
  std::printf("], \"volume_error_m3\": %.6g, \"velocities\": %s, \"sums\": %s", volume_error,
              s.velocities ? "true" : "false", s.sums ? "true" : "false");
  if (s.sums)
    std::printf(", \"sums_volume_m3\": %.9g, \"sums_max_depth_m\": %.6g", last_volume,
                static_cast<double>(last_deepest));
  std::printf("}\n");
  return 0;
}
