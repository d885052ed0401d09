// Assimp in a child process (mesh_reader.h). The child reads the file, copies what the project
// uses into one buffer in an anonymous memory file (memfd) and ends with _exit; the parent waits
// for it with a deadline, then checks and unpacks the buffer. Under sanitizers the child gets no
// memory limit (their shadow memory needs terabytes of address space).
#include "mesh_reader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>

#include <chrono>
#include <csignal>
#include <cstring>
#include <exception>
#include <fstream>
#include <mutex>
#include <string_view>
#include <thread>

#include "memory_budget.h"

#if defined(__SANITIZE_ADDRESS__)
#define SB_UNDER_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SB_UNDER_SANITIZER 1
#endif
#endif

namespace sb {

namespace fs = std::filesystem;

int RawMeshPart::uv_channel_count() const {
  int n = 0;
  while (n < kMaxUvChannels && !uvs[std::size_t(n)].empty()) ++n;
  return n;
}

namespace {

constexpr std::uint32_t kMagic = 0x524d4253;  // "SBMR"

// Assimp's log: one global logger, whose stream collects what the reader warns about.
class CapturedLog : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    std::string m = message ? message : "";
    while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
    messages.push_back(std::move(m));
  }
  std::vector<std::string> messages;
};

CapturedLog& assimp_log() {
  static CapturedLog* log = [] {
    Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
    auto* stream = new CapturedLog;  // owned by the logger from here on
    Assimp::DefaultLogger::get()->attachStream(stream, Assimp::Logger::Warn | Assimp::Logger::Err);
    return stream;
  }();
  return *log;
}

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_string(const std::string& s) {
    put(std::uint64_t(s.size()));
    bytes.append(s);
  }
  template <class T>
  void put_array(const std::vector<T>& v) {
    put(std::uint64_t(v.size()));
    if (!v.empty()) bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string bytes;
};

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

std::string one_line(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// What the child does: read, copy out, pack. Status 0 and the parts, or 1 and the error.
std::string read_and_pack(const fs::path& file) {
  Writer out;
  out.put(kMagic);
  CapturedLog& log = assimp_log();
  log.messages.clear();
  std::string error;
  std::vector<RawMeshPart> parts;
  try {
    Assimp::Importer importer;
    const unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices |
                           aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(file.string(), flags);
    if (!scene) {
      error = one_line(importer.GetErrorString());
    } else if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) {
      error = "the file holds no complete mesh";
    } else {
      for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* am = scene->mMeshes[m];
        RawMeshPart part;
        const auto copy = [&](const aiVector3D* v, std::vector<float>& to) {
          to.resize(std::size_t(am->mNumVertices) * 3);
          for (unsigned i = 0; i < am->mNumVertices; ++i) {
            to[3 * i] = v[i].x;
            to[3 * i + 1] = v[i].y;
            to[3 * i + 2] = v[i].z;
          }
        };
        copy(am->mVertices, part.positions);
        if (am->HasNormals()) copy(am->mNormals, part.normals);
        for (unsigned c = 0; c < unsigned(kMaxUvChannels); ++c) {
          if (!am->HasTextureCoords(c)) break;  // channels are used from 0 on
          copy(am->mTextureCoords[c], part.uvs[c]);
        }
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
          const aiFace& face = am->mFaces[f];
          if (face.mNumIndices != 3) continue;
          for (unsigned k = 0; k < 3; ++k) {
            if (face.mIndices[k] >= am->mNumVertices) {
              error = fmt::format("mesh {} face {} names vertex {} of {}", m, f, face.mIndices[k],
                                  am->mNumVertices);
              break;
            }
            part.triangles.push_back(face.mIndices[k]);
          }
        }
        parts.push_back(std::move(part));
      }
    }
  } catch (const std::exception& e) {
    error = one_line(e.what());
  }
  out.put(std::uint32_t(error.empty() ? 0 : 1));
  out.put_string(error);
  out.put(std::uint64_t(log.messages.size()));
  for (const std::string& m : log.messages) out.put_string(one_line(m));
  out.put(std::uint64_t(error.empty() ? parts.size() : 0));
  if (error.empty()) {
    for (const RawMeshPart& p : parts) {
      out.put_array(p.positions);
      out.put_array(p.normals);
      for (const auto& uv : p.uvs) out.put_array(uv);
      out.put_array(p.triangles);
    }
  }
  return out.bytes;
}

Expected<RawMeshFile> unpack(std::string_view bytes) {
  Reader in(bytes);
  std::uint32_t magic = 0, status = 0;
  std::string error;
  std::uint64_t messages = 0, parts = 0;
  const auto broken = [] { return scene_error("the mesh reader's answer is incomplete"); };
  if (!in.get(magic) || magic != kMagic || !in.get(status) || !in.get_string(error) ||
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
    if (!in.get_array(p.triangles)) return broken();
    const std::size_t n = p.positions.size();
    bool sizes =
        n % 3 == 0 && (p.normals.empty() || p.normals.size() == n) && p.triangles.size() % 3 == 0;
    for (const auto& uv : p.uvs) sizes = sizes && (uv.empty() || uv.size() == n);
    for (std::uint32_t index : p.triangles) sizes = sizes && index < n / 3;
    if (!sizes) return broken();
    file.parts.push_back(std::move(p));
  }
  if (!in.done()) return broken();
  return file;
}

// Forks are made one at a time: the child of a process that forks from two threads at once could
// inherit a lock another thread held.
std::mutex kForkMutex;

}  // namespace

Expected<RawMeshFile> read_mesh_file(const fs::path& file, const MeshReadLimits& limits) {
  const std::lock_guard lock(kForkMutex);
  const int fd = ::memfd_create("shadowbake-mesh", MFD_CLOEXEC);
  if (fd < 0)
    return scene_error(std::string("cannot start the mesh reader: ") + std::strerror(errno));
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fd);
    return scene_error(std::string("cannot start the mesh reader: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // A crash of Assimp's ends the child with its signal, which the parent reports; handlers
    // inherited from the parent (a sanitizer's, a fuzzer's) would report it as their own.
    for (const int signal : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT})
      std::signal(signal, SIG_DFL);
#ifndef SB_UNDER_SANITIZER
    // Heap and anonymous mappings beyond what the process already holds.
    struct rlimit data = {};
    std::ifstream status("/proc/self/status");
    std::uint64_t held_kib = 0;
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmData:", 0) == 0) held_kib = std::stoull(line.substr(7));
    data.rlim_cur = data.rlim_max = rlim_t(held_kib * 1024 + limits.max_memory);
    ::setrlimit(RLIMIT_DATA, &data);
#endif
    const std::string packed = read_and_pack(file);
    std::size_t written = 0;
    while (written < packed.size()) {
      const ssize_t n = ::write(fd, packed.data() + written, packed.size() - written);
      if (n <= 0) ::_exit(3);
      written += std::size_t(n);
    }
    ::_exit(0);
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
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || bytes.empty()) {
    return scene_error(fmt::format(
        "Assimp gave up reading it (exit status {}; it may need more "
        "than the {} it may use)",
        WIFEXITED(status) ? WEXITSTATUS(status) : -1, format_bytes(double(limits.max_memory))));
  }
  return unpack(bytes);
}

}  // namespace sb
