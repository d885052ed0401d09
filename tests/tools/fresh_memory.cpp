// How much the first touch of fresh memory costs on this machine, and how that depends on how
// long ago memory was last freed (a virtual machine may hand freed pages back to its host, which
// must back them again on their next touch). Developer tool, not part of the build:
//
//   g++ -O2 -pthread tests/tools/fresh_memory.cpp -o /tmp/fresh_memory
//   /tmp/fresh_memory GIB THREADS PAUSE...
//
// For each PAUSE (seconds): touches GIB GiB with THREADS threads and frees it, waits PAUSE
// seconds, then times the first touch of another GIB GiB (2 MiB pages advised, as the
// shadowbake executable advises its large allocations). docs/methods.md ("Suns at 4096²") quotes
// its figures.
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

namespace {

double touch(std::size_t bytes, int threads) {
  char* p = static_cast<char*>(std::aligned_alloc(std::size_t(2) << 20, bytes));
  if (p == nullptr) {
    std::fprintf(stderr, "fresh_memory: cannot allocate %zu bytes\n", bytes);
    std::exit(1);
  }
  madvise(p, bytes, MADV_HUGEPAGE);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  const std::size_t share = bytes / std::size_t(threads);
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([=] { std::memset(p + std::size_t(t) * share, 1, share); });
  for (std::thread& t : pool) t.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::free(p);
  return seconds;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: fresh_memory GIB THREADS PAUSE...\n");
    return 2;
  }
  const std::size_t bytes = std::size_t(std::atof(argv[1]) * double(std::size_t(1) << 30));
  const int threads = std::max(1, std::atoi(argv[2]));
  for (int i = 3; i < argc; ++i) {
    const double pause = std::atof(argv[i]);
    touch(bytes, threads);
    std::this_thread::sleep_for(std::chrono::duration<double>(pause));
    const double seconds = touch(bytes, threads);
    std::printf("%.3g GiB, %d thread(s), %g s after the last free: %.3f s (%.2f ns per byte)\n",
                double(bytes) / double(std::size_t(1) << 30), threads, pause, seconds,
                1e9 * seconds / double(bytes));
  }
  return 0;
}
