// Freed memory back to the system promptly (glibc), for the programs whose
// stages allocate and free arrays as large as the mesh (the encoder).
#pragma once

#include <cstdlib>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace meshstream {

// glibc gives a large allocation its own mapping (unmapped on free) only
// above its mmap threshold, and raises that threshold to the size of every
// such block freed, up to 32 MiB: once the first big array is freed, later
// ones of that size come from the main heap, where a freed block stays
// resident while anything above it lives. An encode frees and allocates
// per-vertex arrays stage by stage, so its peak RSS grew by a fifth
// (400k-vertex mesh: 212 MB, 170 MB with fixed thresholds). Fixed
// thresholds turn the adjustment off. Call once, early in main.
inline void keep_heap_tight() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);  // glibc's initial value, kept
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024);
#endif
}

}  // namespace meshstream
