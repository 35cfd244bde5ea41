// erodem — field arrays at different offsets modulo 4 KiB (kernels/stagger.hpp): the slots
// the OpenCL backend's sub-buffers and the CPU reference's allocator use.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
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

}  // namespace
}  // namespace erodem::test
