#include "scenewatch/service/access_token.h"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <cstdio>

#include "scenewatch/core/files.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kTokenBytes = 32;  // 256 bits, written as 64 hex digits
constexpr std::size_t kMinTokenChars = 16;
constexpr std::size_t kMaxTokenChars = 4096;

std::string errno_text(int err) { return std::strerror(err); }

std::string mode_text(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}

/// Checks the opened file and reads the token from it.
Result<std::string> read_from(int fd, const fs::path& path) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return io_error(quoted(path) + ": cannot stat: " + errno_text(errno));
  if (!S_ISREG(st.st_mode)) return invalid_argument(quoted(path) + ": the token file is not a regular file");
  if (st.st_uid != ::geteuid()) {
    return Error{ErrorCode::kPermissionDenied, quoted(path) + ": the token file belongs to user " + std::to_string(st.st_uid) +
                                   ", not to this user (" + std::to_string(::geteuid()) + ")"};
  }
  if ((st.st_mode & 077) != 0) {
    return Error{ErrorCode::kPermissionDenied, quoted(path) + ": the token file has mode " + mode_text(st.st_mode) +
                                   ": others may read it; make it readable by its owner only (chmod 600)"};
  }
  if (st.st_size > static_cast<off_t>(kMaxTokenChars + 2)) {
    return invalid_argument(quoted(path) + ": the token file holds " + std::to_string(st.st_size) +
                            " bytes, more than a token (at most " + std::to_string(kMaxTokenChars) + " characters)");
  }
  std::string text(kMaxTokenChars + 2, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return io_error(quoted(path) + ": cannot read: " + errno_text(errno));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  if (text.size() < kMinTokenChars || text.size() > kMaxTokenChars) {
    return invalid_argument(quoted(path) + ": the token must be " + std::to_string(kMinTokenChars) + " to " +
                            std::to_string(kMaxTokenChars) + " characters, the file holds " +
                            std::to_string(text.size()));
  }
  for (const char c : text) {
    if (c <= ' ' || c > '~') return invalid_argument(quoted(path) + ": the token holds a non-printable character");
  }
  return text;
}

/// The token file's folder and every folder above it: none may be writable by every user without
/// the sticky bit, or anyone could rename the token file (or its folder) away and put their own
/// in its place, and the daemon would take their token.
Status check_folders(const fs::path& path) {
  std::error_code ec;
  fs::path dir = fs::absolute(path, ec).parent_path();
  for (; !dir.empty(); dir = dir.parent_path()) {
    struct stat st {};
    if (::stat(dir.c_str(), &st) == 0 && (st.st_mode & S_IWOTH) != 0 && (st.st_mode & S_ISVTX) == 0) {
      return Error{ErrorCode::kPermissionDenied,
                   quoted(path) + ": the token file lies in " + quoted(dir) + ", which every user may write to (mode " +
                       mode_text(st.st_mode) + ") without the sticky bit: anyone could put their own token file in "
                       "its place. Keep the token in a folder only you can write to (or chmod o-w, or +t, that folder)"};
    }
    if (dir == dir.root_path()) break;
  }
  return {};
}

Result<std::string> open_and_read(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) return not_found(quoted(path) + ": no such token file");
    if (err == ELOOP) return invalid_argument(quoted(path) + ": the token file is a symlink");
    return io_error(quoted(path) + ": cannot open the token file: " + errno_text(err));
  }
  auto token = read_from(fd, path);
  ::close(fd);
  return token;
}

Result<std::string> random_token() {
  unsigned char bytes[kTokenBytes];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return io_error("getrandom failed: " + errno_text(errno));
    got += static_cast<std::size_t>(n);
  }
  static const char kHex[] = "0123456789abcdef";
  std::string token;
  for (const unsigned char b : bytes) {
    token += kHex[b >> 4];
    token += kHex[b & 15];
  }
  return token;
}

}  // namespace

fs::path default_token_path() {
  const char* home = std::getenv("HOME");
  if (home == nullptr || *home == '\0') return {};
  return fs::path(home) / ".scenewatch" / "token";
}

Result<std::string> read_token_file(const fs::path& path) {
  if (path.empty()) return invalid_argument("no token file: HOME is not set; name one (server.token_file, --token-file)");
  if (Status s = check_folders(path); !s) return s.error();
  return open_and_read(path);
}

Result<std::string> ensure_token_file(const fs::path& path) {
  auto existing = read_token_file(path);
  if (existing || existing.error().code != ErrorCode::kNotFound) return existing;

  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) return io_error(quoted(dir) + ": cannot create the token file's folder: " + ec.message());
    fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace, ec);
  }
  auto token = random_token();
  if (!token) return token.error();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return read_token_file(path);  // another daemon made it meanwhile
    return io_error(quoted(path) + ": cannot create the token file: " + errno_text(errno));
  }
  const std::string line = *token + "\n";
  std::size_t written = 0;
  Status status;
  while (written < line.size()) {
    const ssize_t n = ::write(fd, line.data() + written, line.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      status = io_error(quoted(path) + ": cannot write the token file: " + errno_text(errno));
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (status && ::fsync(fd) != 0) status = io_error(quoted(path) + ": cannot fsync the token file: " + errno_text(errno));
  ::close(fd);
  if (!status) {
    fs::remove(path, ec);
    return status.error();
  }
  return token;
}

bool tokens_equal(std::string_view given, std::string_view expected) {
  // Every byte of `expected` is compared whatever the earlier ones gave; a shorter `given` is
  // padded with zeros (and differs by its length anyway).
  volatile unsigned char diff = given.size() == expected.size() ? 0 : 1;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const unsigned char g = i < given.size() ? static_cast<unsigned char>(given[i]) : 0;
    diff = static_cast<unsigned char>(diff | (g ^ static_cast<unsigned char>(expected[i])));
  }
  return diff == 0;
}

}  // namespace scenewatch::service
