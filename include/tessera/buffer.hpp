// Buffer<T>: the array type of large results (cells, mesh, simplices).
//
// A std::vector in every respect but one: growing it by resize() leaves the
// new elements of a trivial type uninitialized instead of zeroing them. The
// compositors size an output once and then fill every element in parallel;
// with std::vector the resize alone zeroed hundreds of megabytes on one
// thread (every page faulted in and cleared twice while the other thread
// idled). Explicit values (assign(n, v), resize(n, v), push_back) behave as
// usual. Any code that resize()s a Buffer must write every new element.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace tessera {

namespace detail {
/// From this size up, Buffer's storage comes from allocate_large.
inline constexpr std::size_t huge_page_bytes = std::size_t{2} << 20;
/// `bytes` (>= huge_page_bytes) aligned to huge_page_bytes, advised for
/// transparent huge pages unless TESSERA_HUGE_PAGES=0 (read once); throws
/// std::bad_alloc like operator new.
void* allocate_large(std::size_t bytes);
/// Frees what allocate_large(bytes) returned.
void deallocate_large(void* p, std::size_t bytes) noexcept;
}  // namespace detail

/// std::allocator whose value-less construct() default-initializes.
template <class T>
class DefaultInitAllocator : public std::allocator<T> {
 public:
  using value_type = T;
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() noexcept = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::huge_page_bytes) return static_cast<T*>(detail::allocate_large(bytes));
    return std::allocator<T>::allocate(n);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::huge_page_bytes) detail::deallocate_large(p, bytes);
    else std::allocator<T>::deallocate(p, n);
  }

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  friend bool operator==(const DefaultInitAllocator&, const DefaultInitAllocator<U>&) noexcept {
    return true;
  }
};

template <class T>
using Buffer = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace tessera
