#pragma once
// One writer at a time in an output folder (issue #45): an advisory lock, flock(2) on
// `.ncfsim_lock`, taken before a run, workflow, render, report or export writes anything there and
// held until the object goes. The kernel drops the lock when its process dies (kill -9 and a lost
// MPI rank included), so a lock file left by a dead process is simply taken over: no pid guessing
// decides whether a folder is in use. The file names its holder (pid, host, command, start) for
// the message of the process that is refused and for `ncfsim status`. flock works across hosts on
// NFS (Linux emulates it with POSIX record locks there).
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace ncfsim::workflow {

/// The lock file's name (left out of the manifest and of the "files ncfsim did not write" check).
inline constexpr const char* kFolderLockFile = ".ncfsim_lock";

class FolderLock {
 public:
  /// Takes the lock of dir (created when missing) for `what` ("run", "workflow", "render", ...).
  /// InputError naming the folder and the holder (pid, host, command, since) when another
  /// process holds it: exit 2, nothing written.
  static std::unique_ptr<FolderLock> acquire(const std::filesystem::path& dir,
                                             const std::string& what);
  /// Whether a live process holds dir's lock (a short test: takes and drops it when free).
  static bool held(const std::filesystem::path& dir);
  /// What the lock file says of its last holder (pid, host, command, what, since); null when
  /// there is no readable lock file.
  static nlohmann::json last_holder(const std::filesystem::path& dir);

  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  /// Removes the lock file, then drops the lock (every exit path that unwinds).
  ~FolderLock();

 private:
  FolderLock(std::filesystem::path file, int fd) : file_(std::move(file)), fd_(fd) {}
  std::filesystem::path file_;
  int fd_ = -1;
};

/// The command line of this process as one string (for the lock file and messages).
std::string this_command_line();

}  // namespace ncfsim::workflow
