// The executable's global operator new: malloc, and an allocation of kHugePageWorthy bytes or
// more advised onto transparent huge pages before anything touches it (core/huge_pages.h says
// why). glibc serves such sizes with fresh mmap'd memory, so the advice lands before the first
// fault; delete is free() as before. Only the plain, nothrow and sized forms are replaced: the
// array forms forward to them by the standard's defaults, and the aligned forms stay the
// library's own.
#include <cstdlib>
#include <new>

#include "core/huge_pages.h"

namespace {

void* allocate(std::size_t bytes) noexcept {
  void* p = std::malloc(bytes == 0 ? 1 : bytes);
  if (p != nullptr && bytes >= sb::kHugePageWorthy) sb::advise_huge_pages(p, bytes);
  return p;
}

}  // namespace

void* operator new(std::size_t bytes) {
  for (;;) {
    if (void* p = allocate(bytes)) return p;
    std::new_handler handler = std::get_new_handler();
    if (handler == nullptr) throw std::bad_alloc();
    handler();
  }
}

void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(bytes);
  } catch (...) {
    return nullptr;
  }
}

void operator delete(void* p) noexcept { std::free(p); }

void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }

void operator delete(void* p, std::size_t) noexcept { std::free(p); }
