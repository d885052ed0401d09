// Byte counts as people write and read them, and the machine's physical memory: what the memory
// budget (pipeline/memory_budget.h) and every reader that limits its input sizes share.
#pragma once

#include <cstdint>
#include <string>

namespace sb {

// A byte count as people read it: "4.2 GiB", "512 MiB", "730 B".
std::string format_bytes(double bytes);

// Physical memory of the machine, bytes (sysconf); 0 when unknown.
std::uint64_t physical_memory_bytes();

// The default of [bake] max_memory: three quarters of the physical memory (at least 1 GiB),
// leaving the rest to the system and to what the estimates do not count (libraries, meshes).
std::uint64_t default_max_memory();

// Parses "8 GiB", "512MiB", "2 GB", "1.5GiB" or a plain number of bytes; false when it is none.
bool parse_memory_size(const std::string& text, std::uint64_t& bytes);

// One large allocation a bake will make, estimated before it is made (pipeline/memory_budget.h).
struct MemoryItem {
  std::string what;  // "texel space", "lightmaps", ...
  double bytes = 0;
};

}  // namespace sb
