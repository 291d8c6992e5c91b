#include "workflow/output/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <fstream>

#include "fem/errors.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {

std::string host_name() {
  char buf[256] = {};
  return gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string("?");
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string read_fd(int fd) {
  std::string text;
  char buf[4096];
  if (lseek(fd, 0, SEEK_SET) != 0) return text;
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;)
    text.append(buf, static_cast<std::size_t>(n));
  return text;
}

// "process 1234 on host h (ncfsim run case.toml -o out, a run since 2026-12-06T02:40:00Z)"
std::string describe_holder(const nlohmann::json& h) {
  if (!h.is_object()) return "another process (starting up)";
  return "process " + std::to_string(h.value("pid", -1)) + " on host " + h.value("host", "?") +
         " (" + h.value("command", "?") + ", a " + h.value("what", "run") + " since " +
         h.value("since", "?") + ")";
}

}  // namespace

std::string this_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!all.empty() && all.back() == '\0') all.pop_back();
  for (char& c : all)
    if (c == '\0') c = ' ';
  return all;
}

std::unique_ptr<FolderLock> FolderLock::acquire(const std::filesystem::path& dir,
                                                const std::string& what) {
  namespace fs = std::filesystem;
  const fs::path file = dir / kFolderLockFile;
  // The command-line argument the folder came from: -o for the writers of a run, the OUTDIR
  // argument for the commands that work on a finished run.
  const std::string key =
      what == "render" || what == "report" || what == "export" || what == "status" ? "OUTDIR"
                                                                                   : "-o";
  // A holder removes the file as it ends: the file opened may be gone (or replaced) by the time
  // its lock is granted; then the lock is on a dead inode and the open is tried again.
  for (int attempt = 0; attempt < 8; ++attempt) {
    const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw InputError(
          dir.string(), key,
          std::string("cannot be written (its lock file: ") + std::strerror(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      // The holder writes its note just after its lock is granted: a moment's wait names it.
      nlohmann::json h = nlohmann::json::parse(read_fd(fd), nullptr, false);
      for (int wait = 0; err == EWOULDBLOCK && !h.is_object() && wait < 100; ++wait) {
        ::usleep(20'000);
        h = nlohmann::json::parse(read_fd(fd), nullptr, false);
      }
      ::close(fd);
      if (err == EWOULDBLOCK)
        throw InputError(dir.string(), key,
                         "is in use by " + describe_holder(h) +
                             ": one run writes into a folder at a time; wait for it to end, or "
                             "give another output folder");
      throw InputError(dir.string(), key,
                       std::string("cannot be locked for this run (") + std::strerror(err) +
                           "): give a folder on a file system with locks");
    }
    struct stat open_st {
    }, path_st{};
    if (::fstat(fd, &open_st) != 0 || ::stat(file.c_str(), &path_st) != 0 ||
        open_st.st_ino != path_st.st_ino || open_st.st_dev != path_st.st_dev) {
      ::close(fd);
      continue;
    }
    const nlohmann::json h = {{"pid", static_cast<long>(::getpid())},
                              {"host", host_name()},
                              {"command", this_command_line()},
                              {"what", what},
                              {"since", utc_now()}};
    const std::string text = h.dump() + "\n";
    // Diagnostics only: a lock whose note could not be written still locks.
    if (::ftruncate(fd, 0) == 0 && ::lseek(fd, 0, SEEK_SET) == 0) {
      [[maybe_unused]] const ssize_t n = ::write(fd, text.data(), text.size());
    }
    return std::unique_ptr<FolderLock>(new FolderLock(file, fd));
  }
  throw InputError(dir.string(), key,
                   "its lock file kept changing under this run (another ncfsim starting and "
                   "ending there?): try again");
}

bool FolderLock::held(const std::filesystem::path& dir) {
  const std::filesystem::path file = dir / kFolderLockFile;
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool busy = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // drops the shared lock when it was granted
  return busy;
}

nlohmann::json FolderLock::last_holder(const std::filesystem::path& dir) {
  return read_json_file(dir / kFolderLockFile);
}

FolderLock::~FolderLock() {
  ::unlink(file_.c_str());  // while still holding: the next process opens a new file
  ::close(fd_);
}

}  // namespace ncfsim::workflow
