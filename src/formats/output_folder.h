// The folder a command publishes its files into, all or nothing. Every file is written into a
// private staging folder inside the output folder, and published by renames only once all were
// written; a lock keeps two shadowbake processes from writing one folder at once; a bake killed
// while it publishes is finished by the next process that opens the folder (a journal in the
// staging folder lists what to rename); staging folders of killed bakes that had not started
// publishing are removed. A failed or interrupted command leaves the previous files as they were.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace sb {

class OutputFolder {
 public:
  // Creates `dir` if missing, takes its lock (flock on the folder), finishes or removes
  // what interrupted processes left there, and makes a fresh staging folder. Errors (exit code
  // "cannot write") name the folder: unwritable, not a folder, or locked by another process.
  static Expected<OutputFolder> open(const std::filesystem::path& dir);

  OutputFolder(OutputFolder&& other) noexcept;
  OutputFolder& operator=(OutputFolder&&) = delete;
  OutputFolder(const OutputFolder&) = delete;
  ~OutputFolder();  // removes an unpublished staging folder, releases the lock

  const std::filesystem::path& dir() const { return dir_; }
  // Where to write the file that `publish` will call `name`: a relative path such as
  // "floor.exr" or "images/floor.png" (its folders are made in the staging folder).
  std::filesystem::path staged(const std::string& name) const;

  // Refuses when something other than a regular file (a folder, a FIFO, a dangling link) stands
  // where one of `names` must go, so that publishing cannot fail half way.
  Status check_targets(const std::vector<std::string>& names) const;

  // Moves every staged file of `names` into the folder. Either all appear, or (an error before
  // the first rename) none does and the previous files stay. SIGINT, SIGTERM and SIGHUP that
  // arrive meanwhile are held until it is done (see interrupt_output_folders).
  Status publish(const std::vector<std::string>& names);

 private:
  OutputFolder() = default;
  std::filesystem::path dir_, staging_;
  int lock_fd_ = -1;
  bool created_dir_ = false;
  bool published_ = false;
};

// For a signal handler (async-signal-safe): removes the staging folder of the process's open
// OutputFolder and returns true, so the handler can let the signal terminate the process; or,
// while a publish is renaming files, returns false and publish finishes first, after which
// pending_interrupt() says which signal to raise again.
bool interrupt_output_folders(int signal) noexcept;
int pending_interrupt() noexcept;

// Writes `text` to `path` (a staged path: no temporary of its own).
Status write_text_file(const std::filesystem::path& path, const std::string& text);

}  // namespace sb
