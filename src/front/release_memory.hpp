// Handing freed heap memory back to the system between a pass's phases.
#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace tessera::front {

/// Return the free pages of malloc's arenas to the system (glibc's
/// malloc_trim; elsewhere nothing). A pass that frees its scratch before
/// allocating its large outputs calls this in between: the scratch was many
/// allocations of a few MB, which glibc serves from arenas it keeps, while
/// the outputs are fresh mappings, so without it the peak resident size
/// holds both.
inline void release_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace tessera::front
