// erodem command line — a STREAM-like memory-bandwidth probe for `erodem bench`.
#pragma once

#include <cstddef>

namespace erodem::cli {

/// Memory bandwidth measured with the copy (c = a) and triad (a = b + s c) kernels of
/// STREAM (McCalpin) over float arrays; bytes counted as STREAM does (copy 8, triad 12
/// bytes per element: the reads and the writes, no write-allocate traffic).
struct Bandwidth {
  std::size_t floats = 0;     ///< elements per array
  std::size_t llc_bytes = 0;  ///< last-level cache size (0: unknown)
  int threads = 1;            ///< OpenMP threads of the multi-threaded runs (all cores)
  int repetitions = 0;        ///< timed repetitions; the values are their medians
  double copy_all = 0.0;      ///< GB/s (1e9 bytes/s), all threads
  double triad_all = 0.0;     ///< GB/s, all threads
  double copy_one = 0.0;      ///< GB/s, one thread
  double triad_one = 0.0;     ///< GB/s, one thread
};

/// Runs the probe: `floats` elements per array (three arrays), each kernel once untimed and
/// then `repetitions` times timed, with all OpenMP threads and with one thread.
Bandwidth measure_bandwidth(std::size_t floats, int repetitions = 5);

/// The size of the largest CPU cache (bytes), 0 when the system does not say.
std::size_t last_level_cache_bytes();

}  // namespace erodem::cli
