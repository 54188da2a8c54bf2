#include "scenewatch/core/files.h"

#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fstream>
#include <system_error>

namespace scenewatch {
namespace fs = std::filesystem;

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

Status check_readable_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(quoted(path) + ": no such file");
  if (!fs::is_regular_file(path, ec)) return invalid_argument(quoted(path) + ": not a regular file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) return io_error(quoted(path) + ": cannot open for reading");
  return {};
}

FileBeneath::FileBeneath(FileBeneath&& other) noexcept
    : fd_(other.fd_), size_(other.size_), dir_(std::move(other.dir_)), alias_(std::move(other.alias_)) {
  other.fd_ = -1;
  other.dir_.clear();
  other.alias_.clear();
}

FileBeneath::~FileBeneath() {
  std::error_code ec;
  if (!dir_.empty()) fs::remove_all(dir_, ec);
  if (fd_ >= 0) ::close(fd_);
}

Status fsync_path(const fs::path& path, bool directory) {
  const int fd = ::open(path.c_str(), (directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) return io_error(quoted(path) + ": cannot open to sync: " + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int sync_errno = errno;
  ::close(fd);
  if (rc != 0) return io_error(quoted(path) + ": fsync failed: " + std::strerror(sync_errno));
  return {};
}

Status with_system_reason(const std::function<Status()>& write) {
  errno = 0;
  Status status = write();
  const int err = errno;
  if (status || err == 0) return status;
  const std::string reason = std::strerror(err);
  Error error = status.error();
  if (error.message.find(reason) == std::string::npos) error.message += ": " + reason;
  return error;
}

Status write_atomically(const fs::path& path, const std::function<Status(const fs::path& tmp)>& write,
                        const std::string& tmp_suffix) {
  std::error_code ec;
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  fs::create_directories(folder, ec);
  const fs::path tmp = path.string() + tmp_suffix;
  if (auto st = write(tmp); !st) {
    fs::remove(tmp, ec);
    return st;
  }
  if (auto st = fsync_path(tmp, false); !st) {
    fs::remove(tmp, ec);
    return st;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return io_error(quoted(path) + ": cannot rename into place: " + ec.message());
  }
  return fsync_path(folder, true);
}

Result<FileBeneath> open_beneath(const fs::path& root, const fs::path& relative) {
  const int dir = ::open(root.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) return io_error(quoted(root) + ": cannot open: " + std::strerror(errno));
  struct open_how how {};
  how.flags = O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK;  // NONBLOCK: a FIFO must not hang the open
  how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
  const int fd = static_cast<int>(::syscall(SYS_openat2, dir, relative.c_str(), &how, sizeof(how)));
  const int open_errno = errno;
  ::close(dir);
  const fs::path full = root / relative;
  if (fd < 0) {
    if (open_errno == EXDEV || open_errno == ELOOP) {
      return Error{ErrorCode::kPermissionDenied, quoted(full) + " leads outside " + quoted(root)};
    }
    if (open_errno == ENOENT) return Error{ErrorCode::kNotFound, quoted(full) + ": no such file"};
    return io_error(quoted(full) + ": cannot open: " + std::strerror(open_errno));
  }
  FileBeneath file;
  file.fd_ = fd;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return invalid_argument(quoted(full) + ": not a regular file");
  file.size_ = static_cast<std::uintmax_t>(st.st_size);
  std::string dir_template = (fs::temp_directory_path() / "scenewatch-open-XXXXXX").string();
  if (::mkdtemp(dir_template.data()) == nullptr) return io_error("cannot make a private folder: " + std::string(std::strerror(errno)));
  file.dir_ = dir_template;
  file.alias_ = file.dir_ / ("file" + relative.extension().string());
  std::error_code ec;
  fs::create_symlink("/proc/self/fd/" + std::to_string(fd), file.alias_, ec);
  if (ec) return io_error(quoted(file.alias_) + ": " + ec.message());
  return file;
}

}  // namespace scenewatch
