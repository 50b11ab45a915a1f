// Large Buffer storage on transparent huge pages (see buffer.hpp).
#include "tessera/buffer.hpp"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tessera::detail {
namespace {
#if defined(__linux__)
// TESSERA_HUGE_PAGES=0 turns the advice off (the storage stays aligned):
// for comparing, or a system where huge pages cost more than they save.
bool advise_enabled() {
  static const bool enabled = [] {
    const char* env = std::getenv("TESSERA_HUGE_PAGES");
    return env == nullptr || std::strcmp(env, "0") != 0;
  }();
  return enabled;
}

// The mapping's length: whole huge pages (the last one is touched only as
// far as it is written).
std::size_t mapped_length(std::size_t bytes) {
  return (bytes + huge_page_bytes - 1) / huge_page_bytes * huge_page_bytes;
}
#endif
}  // namespace

#if defined(__linux__)
// A mapping of its own rather than malloc's: freed, it goes back to the
// system at once. Through malloc, a freed block below glibc's adaptive mmap
// threshold (which rises to the size of each large block freed, up to
// 32 MiB) stays in the heap, and a process that computes cells again and
// again (a Python loop) held ~40% more than it needed (2D 1M: 273 MiB from
// the fifth call on, against 193 MiB).
void* allocate_large(std::size_t bytes) {
  const std::size_t len = mapped_length(bytes);
  if (len < bytes || len + huge_page_bytes < len) throw std::bad_alloc();
  // Map a huge page more than needed, then unmap the slack before the first
  // aligned address and after the length.
  void* m = mmap(nullptr, len + huge_page_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (m == MAP_FAILED) throw std::bad_alloc();
  const auto base = reinterpret_cast<std::uintptr_t>(m);
  const std::uintptr_t aligned = (base + huge_page_bytes - 1) & ~(std::uintptr_t{huge_page_bytes} - 1);
  const std::size_t head = aligned - base, tail = huge_page_bytes - head;
  if (head != 0) munmap(m, head);
  if (tail != 0) munmap(reinterpret_cast<void*>(aligned + len), tail);
  void* p = reinterpret_cast<void*>(aligned);
#if defined(MADV_HUGEPAGE)
  // Advice, not a requirement: without THP support the call fails and
  // nothing changes.
  if (advise_enabled()) (void)madvise(p, len, MADV_HUGEPAGE);
#endif
  return p;
}

void deallocate_large(void* p, std::size_t bytes) noexcept { munmap(p, mapped_length(bytes)); }
#else
void* allocate_large(std::size_t bytes) {
  return ::operator new(bytes, std::align_val_t{huge_page_bytes});
}

void deallocate_large(void* p, std::size_t /*bytes*/) noexcept {
  ::operator delete(p, std::align_val_t{huge_page_bytes});
}
#endif

}  // namespace tessera::detail
