// Large arrays sized without a serial first write, for their first writes to be parallel.
#pragma once

#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace sb {

// An allocator for large arrays (texel records, per-texel values, images): std::allocator, but an
// element made without a value (resize, or a count) is left as the memory holds it, so that an
// array is sized without being written and then written once, in parallel. A 4096² receiver's
// texel records are half a gigabyte, and on a virtual machine every first touch of a page is a
// fault: a serial first write (std::vector::resize) spends its time in the kernel zeroing pages
// on one core. For types whose storage may be assigned without a constructor run first: scalars,
// aggregates (Texel) and Eigen's fixed-size vectors, whose default constructor writes nothing.
template <typename T>
struct FreshAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = FreshAllocator<U>;
  };
  FreshAllocator() = default;
  template <typename U>
  FreshAllocator(const FreshAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U*) noexcept {
    static_assert(std::is_trivially_destructible_v<U>,
                  "FreshAllocator leaves storage to be assigned");
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T>
using FreshVector = std::vector<T, FreshAllocator<T>>;

}  // namespace sb
