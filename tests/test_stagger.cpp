// erodem — field arrays at different offsets modulo 4 KiB (kernels/stagger.hpp): the slots
// the OpenCL backend's sub-buffers and the CPU reference's allocator use.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <set>
#include <vector>

#include "stagger.hpp"

namespace erodem::test {
namespace {

/// The number of distinct offsets among the first `slots` slots at alignment `align`.
std::size_t distinct_offsets(std::size_t slots, std::size_t align) {
  std::set<std::size_t> seen;
  for (std::size_t k = 0; k < slots; ++k) {
    const std::size_t offset = stagger_offset(k, align);
    EXPECT_EQ(offset % align, 0u) << "slot " << k;
    EXPECT_LT(offset, kStaggerPeriod) << "slot " << k;
    seen.insert(offset);
  }
  return seen.size();
}

TEST(Stagger, SlotsSpreadOverThePageAtEveryAlignment) {
  // PoCL's sub-buffers start at multiples of 128 bytes, NVIDIA's of 512 (and 4096 is no
  // staggering at all).
  const std::size_t at128 = distinct_offsets(32, 128), at512 = distinct_offsets(8, 512);
  const std::size_t at64 = distinct_offsets(32, 64), at4096 = distinct_offsets(8, 4096);
  std::printf(
      "distinct offsets: 32 slots at 64 B: %zu, at 128 B: %zu; 8 slots at 512 B: %zu; "
      "at 4096 B: %zu\n",
      at64, at128, at512, at4096);
  EXPECT_EQ(at128, 32u);
  EXPECT_EQ(at64, 32u);
  EXPECT_EQ(at512, 8u);
  EXPECT_EQ(at4096, 1u);
}

TEST(Stagger, AllocatorGivesLargeFieldsTheirOwnOffsets) {
  using Field = std::vector<float, StaggeredAllocator<float>>;
  // Twenty fields of 256 x 256 floats, as the CPU reference holds them, and a small one.
  std::vector<Field> fields;
  for (int k = 0; k < 20; ++k) fields.emplace_back(256 * 256, static_cast<float>(k));
  std::set<std::uintptr_t> offsets;
  for (const auto& f : fields) {
    const auto address = reinterpret_cast<std::uintptr_t>(f.data());
    EXPECT_EQ(address % 128, 0u);
    offsets.insert(address % kStaggerPeriod);
  }
  // The slot counter is process-wide, so the twenty need not start at slot 0; twenty
  // consecutive slots of the 32 are all distinct.
  std::printf("20 fields of 256 KiB: %zu distinct offsets modulo 4096 (bound 20)\n",
              offsets.size());
  EXPECT_EQ(offsets.size(), 20u);
  // The values survive copies, moves and growth (each a new block, freed by deallocate).
  Field copy = fields[7];
  Field moved = std::move(fields[8]);
  copy.resize(copy.size() * 2, -1.0f);
  EXPECT_EQ(copy[0], 7.0f);
  EXPECT_EQ(copy.back(), -1.0f);
  EXPECT_EQ(moved[100], 8.0f);
  const Field small(16, 2.0f);  // below kStaggerMin: plain operator new
  EXPECT_EQ(small[15], 2.0f);
  // Across the threshold: one element short of kStaggerMin bytes, exactly at it, and a vector
  // grown from below to above it (allocate and deallocate must draw the line alike; the
  // sanitizer run checks every block is freed as it was allocated); swap; double.
  Field below(kStaggerMin / sizeof(float) - 1, 1.0f), at(kStaggerMin / sizeof(float), 3.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(at.data()) % 128, 0u);
  for (int k = 0; k < 3; ++k) below.resize(below.size() * 2, 4.0f);
  below.shrink_to_fit();
  EXPECT_EQ(below[0], 1.0f);
  EXPECT_EQ(below.back(), 4.0f);
  std::swap(below, at);
  EXPECT_EQ(below[0], 3.0f);
  EXPECT_EQ(at[0], 1.0f);
  std::vector<double, StaggeredAllocator<double>> doubles(kStaggerMin / sizeof(double), 0.5);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(doubles.data()) % 128, 0u);
  EXPECT_EQ(doubles.back(), 0.5);
}

/// The resident set of this process (bytes), from /proc/self/statm; 0 where there is none.
double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  double size = 0, resident = 0;
  if (!(statm >> size >> resident)) return 0;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

TEST(Stagger, ValueInitialisedFieldsAreZeroWhateverTheMemoryHeld) {
  // resize within the capacity constructs over the old values: 5 and -0 (whose bits are not
  // zero) must become +0.
  using Field = std::vector<float, StaggeredAllocator<float>>;
  for (const float old : {5.0f, -0.0f}) {
    for (const std::size_t n : {std::size_t{1000}, kStaggerMin / sizeof(float) * 2}) {
      Field f(n, old);
      f.resize(10);
      f.resize(n);
      std::size_t wrong = 0;
      for (std::size_t i = 10; i < n; ++i) wrong += f[i] != 0.0f || std::signbit(f[i]);
      EXPECT_EQ(wrong, 0u) << n << " values over " << old;
      EXPECT_EQ(f[0], old);
    }
  }
}

TEST(Stagger, AFieldOfZerosTakesMemoryOnlyWhereWritten) {
#ifndef ERODEM_STAGGER_MMAP
  GTEST_SKIP() << "fields come from operator new in this build (AddressSanitizer or no mmap)";
#else
  using Field = std::vector<float, StaggeredAllocator<float>>;
  const std::size_t n = std::size_t{64} << 20 >> 2;  // 64 MiB of floats
  const double mib = 1024.0 * 1024.0, before = resident_bytes();
  if (before == 0) GTEST_SKIP() << "no /proc/self/statm";
  Field f(n);
  double sum = 0;
  for (std::size_t i = 0; i < n; i += 1024) sum += f[i];  // reads map the zero page
  const double made = resident_bytes();
  for (std::size_t i = 0; i < n / 2; ++i) f[i] = 1.0f;
  const double half = resident_bytes();
  // Bounds: writing the zeros would take the whole 64 MiB at once; the first half's writes
  // must show as 32 MiB (so the measure itself can see them).
  std::printf(
      "a field of 64 MiB of zeros: %.1f MiB resident once made and read (bound 8), "
      "%.1f MiB once half written (bound 28 to 40)\n",
      (made - before) / mib, (half - before) / mib);
  EXPECT_EQ(sum, 0.0);
  EXPECT_LT(made - before, 8 * mib);
  EXPECT_GT(half - before, 28 * mib);
  EXPECT_LT(half - before, 40 * mib);
#endif
}

}  // namespace
}  // namespace erodem::test
