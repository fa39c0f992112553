#include "src/solvers/huge_page_allocator.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>

namespace rig_calibrator {

void* AllocateLarge(size_t bytes) {
  bytes = std::max<size_t>(1, bytes);
  if (bytes < kMinHugePageBytes) return std::malloc(bytes);
  const size_t rounded =
      (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  void* memory = std::aligned_alloc(kHugePageBytes, rounded);
#ifdef MADV_HUGEPAGE
  if (memory != nullptr) madvise(memory, rounded, MADV_HUGEPAGE);  // a hint
#endif
  return memory;
}

void FreeLarge(void* memory) { std::free(memory); }

}  // namespace rig_calibrator
