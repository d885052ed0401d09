// Large allocations on transparent huge pages.
//
// Why: a 4096² receiver's per-texel buffers are gigabytes of fresh memory, and each 4 KiB page is
// a page fault on first touch. In a virtual machine a fault costs more than the work done on its
// page: the sun bake at 4096² (scenes/outdoor/scene_sun.toml) spent 40 % of its time in the
// kernel, faulting. Where the kernel offers transparent huge pages on request (THP "madvise",
// Debian's default), advising a range before it is touched makes its faults 2 MiB ones, 512
// times fewer. glibc's `glibc.malloc.hugetlb=1` tunable advises every allocation so, but only
// when set in the environment before the process starts; the `shadowbake` executable advises its
// large allocations from inside instead (cli/huge_page_new.cpp). Where huge pages are off or
// unknown the advice is a no-op.
#pragma once

#include <cstddef>

namespace sb {

// Allocations of this many bytes or more are worth advising.
inline constexpr std::size_t kHugePageWorthy = std::size_t(4) << 20;

// Advises the 2 MiB-aligned pages inside [data, data + bytes) as huge pages (madvise
// MADV_HUGEPAGE); ranges that hold no whole huge page are left alone.
void advise_huge_pages(void* data, std::size_t bytes);

}  // namespace sb
