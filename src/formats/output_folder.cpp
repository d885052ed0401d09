// All-or-nothing output folders (output_folder.h). Why each piece:
// - Staging inside the output folder: renames within one file system are atomic, so each file
//   appears whole; copying from /tmp would not be.
// - A journal (`.publish`, written and synced before the first rename): a process killed between
//   renames leaves old and new files mixed; the next process to open the folder sees the journal
//   and finishes the renames, so the mix lasts only until then. Without a journal a staging
//   folder is an unfinished bake and is removed.
// - flock on the output folder itself: the kernel drops the lock when the process dies, however
//   it dies, so a stale lock never blocks a folder, and no lock file is left among the outputs.
// - Signals: the handler may run on any thread, so a state word decides between "remove the
//   staging folder and die" and "publishing: let the renames finish"; the removal uses only
//   system calls (open, getdents64, unlinkat, rmdir), which are async-signal-safe.
#include "formats/output_folder.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

namespace sb {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStagingPrefix = ".shadowbake-staging.";
constexpr const char* kJournalName = ".publish";

// The process's one open staging folder, for the signal handler.
enum State : int { kIdle = 0, kStaging = 1, kPublishing = 2, kRemoving = 3 };
std::atomic<int> g_state{kIdle};
std::atomic<int> g_pending_signal{0};
char g_staging[PATH_MAX] = {};
char g_created_dir[PATH_MAX] = {};  // the output folder, when this process made it

Error folder_error(const fs::path& dir, const std::string& problem) {
  return output_error(dir.string() + ": " + problem);
}

std::string errno_text() { return std::strerror(errno); }

// Removes a folder and what it holds, down to `depth` levels of sub-folders; system calls only.
void remove_tree_at(int parent, const char* name, int depth) noexcept {
  const int fd = ::openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buffer[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (long at = 0; at < n;) {
        struct Entry {
          std::uint64_t inode;
          std::int64_t offset;
          unsigned short length;
          unsigned char type;
          char name[1];
        };
        const auto* e = reinterpret_cast<const Entry*>(buffer + at);
        const bool dot =
            e->name[0] == '.' && (e->name[1] == 0 || (e->name[1] == '.' && e->name[2] == 0));
        if (!dot && ::unlinkat(fd, e->name, 0) != 0 && errno == EISDIR && depth > 0)
          remove_tree_at(fd, e->name, depth - 1);
        at += e->length;
      }
    }
    ::close(fd);
  }
  ::unlinkat(parent, name, AT_REMOVEDIR);
}

Status sync_path(const fs::path& path, bool directory) {
  const int fd = ::open(path.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) return output_error(path.string() + ": cannot open to sync: " + errno_text());
  const int result = ::fsync(fd);
  ::close(fd);
  if (result != 0) return output_error(path.string() + ": cannot sync: " + errno_text());
  return Ok{};
}

std::vector<std::string> read_journal(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> names;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) names.push_back(line);
  return names;
}

// Renames staging/name to dir/name for each name, in order; renames already done are skipped.
Status rename_all(const fs::path& staging, const fs::path& dir,
                  const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    std::error_code ec;
    const fs::path from = staging / name;
    if (!fs::exists(fs::symlink_status(from, ec))) continue;
    fs::create_directories((dir / name).parent_path(), ec);
    if (!ec) fs::rename(from, dir / name, ec);
    if (ec) return output_error((dir / name).string() + ": cannot publish: " + ec.message());
  }
  return Ok{};
}

// Finishes or removes what interrupted processes left in dir (we hold its lock).
Status recover(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) != 0 || !entry.is_directory(ec)) continue;
    const fs::path journal = entry.path() / kJournalName;
    if (fs::exists(journal, ec)) {
      if (Status s = rename_all(entry.path(), dir, read_journal(journal)); !s) return s;
    }
    fs::remove_all(entry.path(), ec);
    if (ec) return folder_error(dir, "cannot remove " + name + ": " + ec.message());
  }
  if (ec) return folder_error(dir, "cannot list the folder: " + ec.message());
  return Ok{};
}

std::string random_suffix() {
  std::random_device device;
  std::ostringstream out;
  out << ::getpid() << "." << std::hex << device() << device();
  return out.str();
}

}  // namespace

Expected<OutputFolder> OutputFolder::open(const fs::path& dir) {
  OutputFolder folder;
  folder.dir_ = dir;
  std::error_code ec;
  const auto status = fs::status(dir, ec);
  if (fs::exists(status)) {
    if (!fs::is_directory(status)) return folder_error(dir, "cannot write here: not a folder");
  } else {
    fs::create_directories(dir, ec);
    if (ec) return folder_error(dir, "cannot create the output folder: " + ec.message());
    folder.created_dir_ = true;
  }

  folder.lock_fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder.lock_fd_ < 0) return folder_error(dir, "cannot open the folder: " + errno_text());
  if (::access(dir.c_str(), W_OK) != 0) {
    return folder_error(dir, "cannot write into the folder: " + errno_text());
  }
  if (::flock(folder.lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    // The holder's staging folder carries its process id.
    std::string pid;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(kStagingPrefix, 0) != 0) continue;
      pid = name.substr(std::strlen(kStagingPrefix));
      pid = pid.substr(0, pid.find('.'));
    }
    return folder_error(dir, "another shadowbake process" +
                                 (pid.empty() ? std::string() : " (pid " + pid + ")") +
                                 " is writing into this folder; wait for it or choose another");
  }

  if (Status s = recover(dir); !s) return s.error();

  folder.staging_ = dir / (kStagingPrefix + random_suffix());
  fs::create_directory(folder.staging_, ec);
  if (ec) return folder_error(dir, "cannot write into the folder: " + ec.message());
  const std::string staging = folder.staging_.string();
  const std::string created = folder.created_dir_ ? dir.string() : std::string();
  if (staging.size() < sizeof g_staging && created.size() < sizeof g_created_dir) {
    std::memcpy(g_staging, staging.c_str(), staging.size() + 1);
    std::memcpy(g_created_dir, created.c_str(), created.size() + 1);
    g_state.store(kStaging);
  }
  return folder;
}

OutputFolder::OutputFolder(OutputFolder&& other) noexcept
    : dir_(std::move(other.dir_)),
      staging_(std::move(other.staging_)),
      lock_fd_(other.lock_fd_),
      created_dir_(other.created_dir_),
      published_(other.published_) {
  other.lock_fd_ = -1;
  other.staging_.clear();
}

OutputFolder::~OutputFolder() {
  std::error_code ec;
  if (!staging_.empty()) {
    int expected = kStaging;
    g_state.compare_exchange_strong(expected, kIdle);
    fs::remove_all(staging_, ec);
  }
  if (lock_fd_ < 0) return;
  if (created_dir_ && !published_) {
    // Nothing was published into the folder this process made: leave no empty folder behind.
    fs::remove(dir_, ec);
  }
  ::close(lock_fd_);
}

fs::path OutputFolder::staged(const std::string& name) const {
  const fs::path path = staging_ / name;
  std::error_code ec;
  if (fs::path(name).has_parent_path()) fs::create_directories(path.parent_path(), ec);
  return path;
}

Status OutputFolder::check_targets(const std::vector<std::string>& names) const {
  for (const std::string& name : names) {
    const fs::path target = dir_ / name;
    std::error_code ec;
    const auto status = fs::symlink_status(target, ec);
    if (!fs::exists(status)) continue;
    if (fs::is_regular_file(status)) continue;
    const char* what = fs::is_directory(status) ? "a folder"
                       : fs::is_symlink(status) ? "a symbolic link"
                                                : "something other than a file";
    return output_error(target.string() + ": cannot write: " + what +
                        " of that name is in the way; move it or choose another output folder");
  }
  return Ok{};
}

Status OutputFolder::publish(const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    std::error_code ec;
    if (!fs::is_regular_file(staged(name), ec)) {
      return output_error((dir_ / name).string() + ": cannot publish: it was not written");
    }
  }
  if (Status s = check_targets(names); !s) return s;
  for (const std::string& name : names)
    if (Status s = sync_path(staged(name), false); !s) return s;
  std::string journal;
  for (const std::string& name : names) journal += name + "\n";
  const fs::path journal_tmp = staging_ / ".publish.tmp";
  if (Status s = write_text_file(journal_tmp, journal); !s) return s;
  if (Status s = sync_path(journal_tmp, false); !s) return s;

  int expected = kStaging;
  if (!g_state.compare_exchange_strong(expected, kPublishing) && expected == kRemoving) {
    // A signal handler is removing the staging folder and will end the process.
    for (;;) ::pause();
  }
  std::error_code ec;
  fs::rename(journal_tmp, staging_ / kJournalName, ec);
  Status result =
      ec ? output_error(dir_.string() + ": cannot publish: " + ec.message()) : Status(Ok{});
  if (result) result = sync_path(staging_, true);
  if (result) result = rename_all(staging_, dir_, names);
  if (result) {
    sync_path(dir_, true);
    fs::remove_all(staging_, ec);
    staging_.clear();
    published_ = true;
  }
  // A failure after the journal leaves it: the next process to open the folder finishes.
  g_state.store(kIdle);
  return result;
}

bool interrupt_output_folders(int signal) noexcept {
  int expected = kStaging;
  if (g_state.compare_exchange_strong(expected, kRemoving)) {
    remove_tree_at(AT_FDCWD, g_staging, 4);
    if (g_created_dir[0] != 0) ::rmdir(g_created_dir);  // only if nothing else is in it
    return true;
  }
  if (expected == kPublishing) {
    g_pending_signal.store(signal);
    return false;
  }
  return true;
}

int pending_interrupt() noexcept { return g_pending_signal.load(); }

Status write_text_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out << text;
  if (out) out.close();
  if (!out) return output_error(path.string() + ": cannot write: " + errno_text());
  return Ok{};
}

}  // namespace sb
