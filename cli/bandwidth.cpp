// The STREAM-like bandwidth probe of `erodem bench` (see bandwidth.hpp).
#include "bandwidth.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace erodem::cli {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

namespace {

using Clock = std::chrono::steady_clock;

// The kernels, each in a multi-threaded (static schedule: each thread touches the part it
// initialised) and a single-threaded version. Signed loop index for OpenMP.
void copy_all(float* c, const float* a, long n) {
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) c[i] = a[i];
}
void triad_all(float* a, const float* b, const float* c, float s, long n) {
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}
void copy_one(float* c, const float* a, long n) {
  for (long i = 0; i < n; ++i) c[i] = a[i];
}
void triad_one(float* a, const float* b, const float* c, float s, long n) {
  for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}

/// GB/s of `bytes` moved by `kernel`, median over `reps` timed runs after one untimed.
template <class F>
double rate(F kernel, double bytes, int reps) {
  kernel();
  std::vector<double> gbs;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = Clock::now();
    kernel();
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    gbs.push_back(bytes / s / 1e9);
  }
  return median(gbs);
}

}  // namespace

std::size_t last_level_cache_bytes() {
  // sysfs first: glibc's _SC_LEVEL3_CACHE_SIZE is wrong on some virtual machines (it says
  // 320 MiB for a 32 MiB L3 here). "32768K" -> bytes.
  int best_level = 0;
  std::size_t best = 0;
  for (int k = 0; k < 8; ++k) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(k);
    std::ifstream level_in(dir + "/level"), size_in(dir + "/size");
    int level = 0;
    std::string size;
    if (!(level_in >> level) || !(size_in >> size) || size.empty()) continue;
    std::size_t mult = 1;
    const char unit = size.back();
    if (unit == 'K') mult = 1024;
    if (unit == 'M') mult = 1024 * 1024;
    if (unit == 'G') mult = 1024UL * 1024 * 1024;
    const std::size_t bytes = std::strtoull(size.c_str(), nullptr, 10) * mult;
    if (level > best_level || (level == best_level && bytes > best)) {
      best_level = level;
      best = bytes;
    }
  }
  if (best > 0) return best;
  long conf = 0;
#ifdef _SC_LEVEL3_CACHE_SIZE
  conf = std::max(conf, sysconf(_SC_LEVEL3_CACHE_SIZE));
#endif
#ifdef _SC_LEVEL2_CACHE_SIZE
  conf = std::max(conf, sysconf(_SC_LEVEL2_CACHE_SIZE));
#endif
  return conf > 0 ? static_cast<std::size_t>(conf) : 0;
}

BandwidthProbe::BandwidthProbe(std::size_t floats, int repetitions)
    : floats_(floats),
      repetitions_(repetitions),
      a_(new float[floats]),
      b_(new float[floats]),
      c_(new float[floats]) {
  const long n = static_cast<long>(floats);
  float *pa = a_.get(), *pb = b_.get(), *pc = c_.get();
  // Uninitialised storage, first touched by the threads that use it in the parallel runs.
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    pa[i] = 1.0f;
    pb[i] = 2.0f;
    pc[i] = 0.0f;
  }
}

void BandwidthProbe::round() {
  Bandwidth bw;
  const long n = static_cast<long>(floats_);
  float *pa = a_.get(), *pb = b_.get(), *pc = c_.get();
  const float s = 3.0f;
  const double copy_bytes = 2.0 * sizeof(float) * static_cast<double>(n);
  const double triad_bytes = 3.0 * sizeof(float) * static_cast<double>(n);
  bw.copy_all = rate([&] { copy_all(pc, pa, n); }, copy_bytes, repetitions_);
  bw.triad_all = rate([&] { triad_all(pa, pb, pc, s, n); }, triad_bytes, repetitions_);
  bw.copy_one = rate([&] { copy_one(pc, pa, n); }, copy_bytes, repetitions_);
  bw.triad_one = rate([&] { triad_one(pa, pb, pc, s, n); }, triad_bytes, repetitions_);
  // Use the results, so no compiler can drop the stores.
  volatile float sink = pa[n / 2] + pc[n - 1];
  (void)sink;
  rounds_.push_back(bw);
}

Bandwidth BandwidthProbe::result() const {
  Bandwidth bw;
  bw.floats = floats_;
  bw.llc_bytes = last_level_cache_bytes();
  bw.repetitions = repetitions_;
  bw.rounds = static_cast<int>(rounds_.size());
#ifdef _OPENMP
  bw.threads = omp_get_max_threads();
#endif
  auto over_rounds = [this](double Bandwidth::*value) {
    std::vector<double> v;
    for (const auto& r : rounds_) v.push_back(r.*value);
    return v;
  };
  const std::vector<double> copies = over_rounds(&Bandwidth::copy_all);
  bw.copy_all = median(copies);
  bw.copy_all_low = copies.empty() ? 0.0 : *std::min_element(copies.begin(), copies.end());
  bw.copy_all_high = copies.empty() ? 0.0 : *std::max_element(copies.begin(), copies.end());
  bw.triad_all = median(over_rounds(&Bandwidth::triad_all));
  bw.copy_one = median(over_rounds(&Bandwidth::copy_one));
  bw.triad_one = median(over_rounds(&Bandwidth::triad_one));
  return bw;
}

}  // namespace erodem::cli
