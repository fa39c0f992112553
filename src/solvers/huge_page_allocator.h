// Memory for the arrays of the bundle adjustments that grow with the number
// of observations (10^6 residuals at 500 framesets x 10 cameras: 36 to 400 MB
// each), in 2 MB pages.
//
// Why. The first touch of every 4 KB page of fresh memory is a page fault,
// and glibc gives every allocation above 32 MB fresh memory (mmap) and
// returns it when freed. On the 2-core VM of the benchmarks a fault costs
// 10-20 us (400 MB: 1.7 s in 4 KB pages, 0.7-1.0 s in 2 MB pages); the
// final bundle adjustment touched 190 000 fresh 4 KB pages, most of them on
// one thread (registering the residuals, building the structure, the
// outlier pruning's per-observation lists). Transparent huge pages, which
// Linux's default "madvise" mode gives only on request, take one fault per
// 2 MB.
//
// From kMinHugePageBytes on, memory is taken 2 MB-aligned and advised
// MADV_HUGEPAGE; smaller blocks would waste much of a 2 MB page and come
// from malloc.
#pragma once

#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace rig_calibrator {

inline constexpr size_t kHugePageBytes = size_t{2} << 20;
inline constexpr size_t kMinHugePageBytes = 4 * kHugePageBytes;

// `bytes` (> 0) of uninitialized memory, in huge pages from
// kMinHugePageBytes on; null when out of memory. Freed by FreeLarge.
void* AllocateLarge(size_t bytes);
void FreeLarge(void* memory);

// A std allocator over AllocateLarge, for std::vector.
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(size_t n) {
    if (n > std::numeric_limits<size_t>::max() / sizeof(T)) {
      throw std::bad_array_new_length();
    }
    void* memory = AllocateLarge(n * sizeof(T));
    if (memory == nullptr) throw std::bad_alloc();
    return static_cast<T*>(memory);
  }
  void deallocate(T* p, size_t) { FreeLarge(p); }
};
template <typename T, typename U>
bool operator==(const HugePageAllocator<T>&, const HugePageAllocator<U>&) {
  return true;
}
template <typename T, typename U>
bool operator!=(const HugePageAllocator<T>&, const HugePageAllocator<U>&) {
  return false;
}

template <typename T>
using LargeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace rig_calibrator
