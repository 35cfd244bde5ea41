// erodem command line — a STREAM-like memory-bandwidth probe for `erodem bench`.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace erodem::cli {

/// Memory bandwidth measured with the copy (c = a) and triad (a = b + s c) kernels of
/// STREAM (McCalpin) over float arrays; bytes counted as STREAM does (copy 8, triad 12
/// bytes per element: the reads and the writes, no write-allocate traffic).
struct Bandwidth {
  std::size_t floats = 0;     ///< elements per array
  std::size_t llc_bytes = 0;  ///< last-level cache size (0: unknown)
  int threads = 1;            ///< OpenMP threads of the multi-threaded runs (all cores)
  int repetitions = 0;        ///< timed repetitions per round; a round's value is their median
  int rounds = 0;             ///< rounds (see BandwidthProbe); the values are their medians
  double copy_all = 0.0;      ///< GB/s (1e9 bytes/s), all threads
  double copy_all_low = 0.0;  ///< the lowest and highest round of copy_all (GB/s)
  double copy_all_high = 0.0;
  double triad_all = 0.0;  ///< GB/s, all threads
  double copy_one = 0.0;   ///< GB/s, one thread
  double triad_one = 0.0;  ///< GB/s, one thread
};

/// The probe's arrays (`floats` elements each, three arrays, first touched by the threads that
/// use them) and its rounds. A round runs each kernel once untimed and then `repetitions`
/// times timed, with all OpenMP threads and with one thread. The bandwidth of a shared
/// virtual machine drifts by tens of per cent within a minute, so `erodem bench` runs a round
/// beside every timed repetition of the kernels and sets them against the median round.
class BandwidthProbe {
 public:
  explicit BandwidthProbe(std::size_t floats, int repetitions = 5);
  BandwidthProbe(const BandwidthProbe&) = delete;
  BandwidthProbe& operator=(const BandwidthProbe&) = delete;
  void round();              ///< runs one round
  Bandwidth result() const;  ///< the medians over the rounds so far (at least one)

 private:
  std::size_t floats_;
  int repetitions_;
  std::unique_ptr<float[]> a_, b_, c_;
  std::vector<Bandwidth> rounds_;
};

/// The median of `v` (0 when empty; the mean of the middle two for an even count).
double median(std::vector<double> v);

/// The size of the largest CPU cache (bytes), 0 when the system does not say.
std::size_t last_level_cache_bytes();

}  // namespace erodem::cli
