// Assimp in a process of its own (mesh_reader.h): read_mesh_file starts the helper executable
// shadowbake_mesh_reader (cli/mesh_reader/main.cpp) with posix_spawn, handing it an anonymous
// memory file (memfd) as descriptor 3; the helper reads the file, writes what the project uses
// there and exits; the parent waits for it with a deadline, then checks and unpacks the buffer.
// A spawned program, not a forked copy of this one: a fork of a process whose other threads
// (TBB's, a sanitizer's allocator) hold a lock gives a child that may wait on it for ever, as a
// bake in the AddressSanitizer suite did.
#include "scene/mesh_reader.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string_view>
#include <system_error>
#include <thread>

#include "core/memory_size.h"

namespace sb {

namespace fs = std::filesystem;

int RawMeshPart::uv_channel_count() const {
  int n = 0;
  while (n < kMaxUvChannels && !uvs[std::size_t(n)].empty()) ++n;
  return n;
}

namespace {

class Reader {
 public:
  explicit Reader(std::string_view b) : bytes_(b) {}
  template <class T>
  bool get(T& v) {
    if (bytes_.size() - at_ < sizeof v) return false;
    std::memcpy(&v, bytes_.data() + at_, sizeof v);
    at_ += sizeof v;
    return true;
  }
  bool get_string(std::string& s) {
    std::uint64_t n = 0;
    if (!get(n) || n > bytes_.size() - at_) return false;
    s.assign(bytes_.data() + at_, n);
    at_ += n;
    return true;
  }
  template <class T>
  bool get_array(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (!get(n) || n > (bytes_.size() - at_) / sizeof(T)) return false;
    v.resize(n);
    if (n > 0) std::memcpy(v.data(), bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return true;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  std::size_t at_ = 0;
};

Expected<RawMeshFile> unpack(std::string_view bytes) {
  Reader in(bytes);
  std::uint32_t magic = 0, status = 0;
  std::string error;
  std::uint64_t messages = 0, parts = 0;
  const auto broken = [] { return scene_error("the mesh reader's answer is incomplete"); };
  if (!in.get(magic) || magic != kMeshReaderMagic || !in.get(status) || !in.get_string(error) ||
      !in.get(messages))
    return broken();
  RawMeshFile file;
  for (std::uint64_t i = 0; i < messages; ++i) {
    std::string m;
    if (!in.get_string(m)) return broken();
    file.warnings.push_back(std::move(m));
  }
  if (status != 0) {
    if (error.find("bad_alloc") != std::string::npos)
      return scene_error("Assimp ran out of the memory it may use reading it");
    return scene_error(error);
  }
  if (!in.get(parts)) return broken();
  for (std::uint64_t i = 0; i < parts; ++i) {
    RawMeshPart p;
    if (!in.get_array(p.positions) || !in.get_array(p.normals)) return broken();
    for (auto& uv : p.uvs)
      if (!in.get_array(uv)) return broken();
    if (!in.get_array(p.triangles) || !in.get(p.material)) return broken();
    const std::size_t n = p.positions.size();
    bool sizes =
        n % 3 == 0 && (p.normals.empty() || p.normals.size() == n) && p.triangles.size() % 3 == 0;
    for (const auto& uv : p.uvs) sizes = sizes && (uv.empty() || uv.size() == n);
    for (std::uint32_t index : p.triangles) sizes = sizes && index < n / 3;
    if (!sizes) return broken();
    file.parts.push_back(std::move(p));
  }
  std::uint64_t count = 0;
  if (!in.get(count)) return broken();
  for (std::uint64_t i = 0; i < count; ++i) {
    RawNode n;
    if (!in.get_string(n.name) || !in.get(n.parent) || !in.get(n.transform) ||
        !in.get_array(n.parts))
      return broken();
    // Depth first: a parent comes before its children, and only the root has none.
    if ((i == 0) != (n.parent < 0) || n.parent >= std::int32_t(i)) return broken();
    for (std::uint32_t part : n.parts)
      if (part >= file.parts.size()) return broken();
    file.nodes.push_back(std::move(n));
  }
  if (file.nodes.empty() || !in.get(count)) return broken();
  for (std::uint64_t i = 0; i < count; ++i) {
    RawMaterial m;
    if (!in.get_string(m.name) || !in.get(m.emissive)) return broken();
    file.materials.push_back(std::move(m));
  }
  if (!in.get(count)) return broken();
  for (std::uint64_t i = 0; i < count; ++i) {
    RawLight l;
    if (!in.get_string(l.name) || !in.get(l.type) || !in.get(l.position) || !in.get(l.direction) ||
        !in.get(l.up) || !in.get(l.color) || !in.get(l.inner_cone) || !in.get(l.outer_cone) ||
        !in.get(l.size))
      return broken();
    file.lights.push_back(std::move(l));
  }
  if (!in.get(file.unit_scale)) return broken();
  if (!in.done()) return broken();
  return file;
}

// Spawns are made one at a time, so that the descriptor made inheritable for one helper is not
// inherited by another.
std::mutex spawn_mutex;

// The helper: $SHADOWBAKE_MESH_READER, else beside the running program (an installed or built
// shadowbake, its tests and tools), else where this build put it.
fs::path helper_path() {
  if (const char* env = std::getenv("SHADOWBAKE_MESH_READER"); env && *env) return env;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path beside = self.parent_path() / "shadowbake_mesh_reader";
    if (fs::is_regular_file(beside, ec)) return beside;
  }
#ifdef SB_MESH_READER_BUILT
  return SB_MESH_READER_BUILT;
#else
  return "shadowbake_mesh_reader";
#endif
}

}  // namespace

Expected<RawMeshFile> read_mesh_file(const fs::path& file, const MeshReadLimits& limits) {
  const fs::path helper = helper_path();
  std::string path = file.string(), memory = std::to_string(limits.max_memory),
              program = helper.string();
  std::vector<char*> argv = {program.data(), path.data(), memory.data(), nullptr};

  const std::unique_lock lock(spawn_mutex);
  const int fd = ::memfd_create("shadowbake-mesh", MFD_CLOEXEC);
  if (fd < 0)
    return scene_error(std::string("cannot start the mesh reader: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  if (fd != 3) {
    posix_spawn_file_actions_adddup2(&actions, fd, 3);  // the copy is inherited
  } else {
    ::fcntl(fd, F_SETFD, 0);
  }
  // Signals at their defaults and none blocked: a crash ends the helper with its signal, which
  // is reported below, whatever the parent (a sanitizer, a fuzzer, the CLI's SIGINT) set up.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t all, none;
  sigfillset(&all);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attributes, &all);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int spawned =
      ::posix_spawn(&pid, program.c_str(), &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (fd == 3) ::fcntl(fd, F_SETFD, FD_CLOEXEC);
  if (spawned != 0) {
    ::close(fd);
    return scene_error(
        fmt::format("cannot start the mesh reader {}: {}", program, std::strerror(spawned)));
  }

  // Wait, with a deadline.
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  bool ended = false;
  for (auto pause = std::chrono::microseconds(200);;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) {
      ended = true;
      break;
    }
    if (done < 0 && errno != EINTR) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
        limits.max_seconds)
      break;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
  if (!ended) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    ::close(fd);
    return scene_error(
        fmt::format("Assimp did not finish reading it in {:.0f} s", limits.max_seconds));
  }
  std::string bytes;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    const off_t size = ::lseek(fd, 0, SEEK_END);
    if (size > 0) {
      bytes.resize(std::size_t(size));
      if (::pread(fd, bytes.data(), bytes.size(), 0) != size) bytes.clear();
    }
  }
  ::close(fd);
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    if (signal == SIGABRT || signal == SIGKILL) {
      return scene_error(fmt::format(
          "Assimp gave up reading it (signal {}; it may need more than the {} it may use)", signal,
          format_bytes(double(limits.max_memory))));
    }
    return scene_error(
        fmt::format("Assimp crashed reading it (signal {}); the file is broken or "
                    "of a kind it misreads",
                    signal));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
    return scene_error(fmt::format("cannot start the mesh reader {}", program));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || bytes.empty()) {
    return scene_error(fmt::format(
        "Assimp gave up reading it (exit status {}; it may need more "
        "than the {} it may use)",
        WIFEXITED(status) ? WEXITSTATUS(status) : -1, format_bytes(double(limits.max_memory))));
  }
  return unpack(bytes);
}

}  // namespace sb
