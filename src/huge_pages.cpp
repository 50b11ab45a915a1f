// Large Buffer storage on transparent huge pages (see buffer.hpp).
#include "tessera/buffer.hpp"

#include <cstdlib>
#include <cstring>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tessera::detail {
namespace {
// TESSERA_HUGE_PAGES=0 turns the advice off (the storage stays aligned):
// for comparing, or a system where huge pages cost more than they save.
bool advise_enabled() {
  static const bool enabled = [] {
    const char* env = std::getenv("TESSERA_HUGE_PAGES");
    return env == nullptr || std::strcmp(env, "0") != 0;
  }();
  return enabled;
}
}  // namespace

void* allocate_large(std::size_t bytes) {
  void* p = ::operator new(bytes, std::align_val_t{huge_page_bytes});
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Only the whole huge pages; the tail stays on small pages. Advice, not a
  // requirement: without THP support the call fails and nothing changes.
  if (advise_enabled()) {
    const std::size_t whole = bytes / huge_page_bytes * huge_page_bytes;
    (void)madvise(p, whole, MADV_HUGEPAGE);
  }
#endif
  return p;
}

void deallocate_large(void* p, std::size_t /*bytes*/) noexcept {
  ::operator delete(p, std::align_val_t{huge_page_bytes});
}

}  // namespace tessera::detail
