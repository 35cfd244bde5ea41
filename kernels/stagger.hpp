// erodem — field arrays that start at different offsets modulo 4 KiB, for both backends.
//
// An allocator hands out large arrays at the same offset modulo the page (glibc's mmap'd
// blocks, PoCL's buffers), so cell i of every field falls into the same set of a CPU's L1
// cache (4 KiB per way) and into the same L2 sets. A cell loop that reads eight fields, some
// of them at rows y - 1 .. y + 2, then asks one set for more lines than it has ways, and the
// lines evict each other. Starting field k at offset k * 1152 modulo 4096 spreads them: with
// the 128-byte steps PoCL's sub-buffers allow, 32 fields before two share an offset.
//
// The large arrays come straight from mmap, whose pages are zero until written and take no
// memory until then (a read maps the kernel's shared zero page), and the allocator's
// value-initialisation (std::vector's size constructor and resize) writes a zero only where
// the memory does not hold one already: a field that starts at zero (the outflows, the
// velocities, ...) takes memory as the steps first write it, not while the run sets up
// (performance.md, "Resident memory per cell"). Each such block is its own mapping, given back
// when freed: a field made and freed within every step would pay its page faults every step.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

#if defined(__SANITIZE_ADDRESS__)
#define ERODEM_STAGGER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ERODEM_STAGGER_ASAN 1
#endif
#endif
// mmap where there is one; AddressSanitizer keeps operator new (it checks the heap's blocks)
#if __has_include(<sys/mman.h>) && !defined(ERODEM_STAGGER_ASAN)
#include <sys/mman.h>
#define ERODEM_STAGGER_MMAP 1
#endif

namespace erodem {

inline constexpr std::size_t kStaggerPeriod = 4096;    ///< bytes: the L1 way size
inline constexpr std::size_t kStaggerStep = 1152;      ///< bytes: 9 x 128, odd in 128-byte units
inline constexpr std::size_t kStaggerMin = 64 * 1024;  ///< bytes: smaller arrays stay as they are

/// The offset (bytes, < kStaggerPeriod) of the array in slot `slot`, rounded down to a
/// multiple of `align` (a power of two; 0 when align >= kStaggerPeriod).
constexpr std::size_t stagger_offset(std::size_t slot, std::size_t align) {
  return align >= kStaggerPeriod ? 0 : (slot * kStaggerStep) % kStaggerPeriod / align * align;
}

/// std::allocator for the CPU reference's fields: arrays of at least kStaggerMin bytes come
/// from a block of whole pages kStaggerPeriod bytes longer (mmap; operator new under
/// AddressSanitizer or without mmap), at the next slot's offset (one process-wide counter);
/// smaller ones from operator new. The offset is the address modulo 4 KiB, so deallocate
/// finds the block without a header. Value-initialisation leaves memory that holds zero bits
/// as it is (above).
template <class T>
struct StaggeredAllocator {
  using value_type = T;
  using is_always_equal = std::true_type;
  using propagate_on_container_move_assignment = std::true_type;

  StaggeredAllocator() noexcept = default;
  template <class U>
  StaggeredAllocator(const StaggeredAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    // (operator new's blocks are zeroed, so construct() reads no indeterminate bytes)
    if (bytes < kStaggerMin) return static_cast<T*>(std::memset(::operator new(bytes), 0, bytes));
    static std::atomic<std::size_t> next{0};
    const std::size_t offset =
        stagger_offset(next.fetch_add(1, std::memory_order_relaxed), alignof(std::max_align_t));
#ifdef ERODEM_STAGGER_MMAP
    void* mapped = ::mmap(nullptr, bytes + kStaggerPeriod, PROT_READ | PROT_WRITE,
                          MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) throw std::bad_alloc();
    auto* block = static_cast<unsigned char*>(mapped);
#else
    auto* block = static_cast<unsigned char*>(
        ::operator new (bytes + kStaggerPeriod, std::align_val_t{kStaggerPeriod}));
    std::memset(block, 0, bytes + kStaggerPeriod);
#endif
    return reinterpret_cast<T*>(block + offset);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kStaggerMin) {
      ::operator delete(p);
      return;
    }
    const auto address = reinterpret_cast<std::uintptr_t>(p);
    void* block = reinterpret_cast<void*>(address - address % kStaggerPeriod);
#ifdef ERODEM_STAGGER_MMAP
    ::munmap(block, bytes + kStaggerPeriod);
#else
    ::operator delete (block, std::align_val_t{kStaggerPeriod});
#endif
  }

  /// Value-initialisation of a number: zero bits, written only where the memory holds others
  /// (a page of a fresh block is then neither written nor taken).
  template <class U>
  void construct(U* p) {
    if constexpr (std::is_arithmetic_v<U>) {
      unsigned char bits[sizeof(U)];
      std::memcpy(bits, static_cast<const void*>(p), sizeof(U));
      for (const unsigned char b : bits)
        if (b != 0) {
          ::new (static_cast<void*>(p)) U();
          return;
        }
    } else {
      ::new (static_cast<void*>(p)) U();
    }
  }
  template <class U, class A, class... Rest>
  void construct(U* p, A&& a, Rest&&... rest) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a), std::forward<Rest>(rest)...);
  }

  template <class U>
  bool operator==(const StaggeredAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const StaggeredAllocator<U>&) const noexcept {
    return false;
  }
};

}  // namespace erodem
