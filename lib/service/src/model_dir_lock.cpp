#include "scenewatch/service/model_directory.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

#include "scenewatch/core/files.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

/// The PID the holder wrote into the lock file, or a phrase saying it is not known.
std::string holder_of(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  std::string pid(text, n > 0 ? static_cast<std::size_t>(n) : 0);
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) return "PID not yet written";
  return "PID " + pid;
}

Status write_pid(int fd, const fs::path& lock_path) {
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    return io_error(quoted(lock_path) + ": cannot write this daemon's PID: " + std::strerror(errno));
  }
  return {};
}

}  // namespace

Result<ModelDirLock> ModelDirLock::acquire(const fs::path& model_dir) {
  std::error_code ec;
  fs::create_directories(model_dir, ec);
  if (ec) return io_error(quoted(model_dir) + ": cannot create the model directory: " + ec.message());
  const fs::path lock_path = model_dir / kModelLockFile;
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) return io_error(quoted(lock_path) + ": cannot open the model directory's lock file: " + std::strerror(errno));
  ModelDirLock lock(fd);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err != EWOULDBLOCK) return io_error(quoted(lock_path) + ": cannot lock: " + std::strerror(err));
    return Error{ErrorCode::kUnavailable,
                 quoted(model_dir) + " is in use by another scenewatchd (" + holder_of(fd) + ", holding " +
                     quoted(lock_path) + "): two daemons on one model directory would overwrite each other's "
                     "saves; stop that one, or give this one another model directory (--model-dir)"};
  }
  if (Status s = write_pid(fd, lock_path); !s) return s.error();
  return Result<ModelDirLock>(std::move(lock));
}

ModelDirLock::ModelDirLock(ModelDirLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

ModelDirLock& ModelDirLock::operator=(ModelDirLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

ModelDirLock::~ModelDirLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

}  // namespace scenewatch::service
