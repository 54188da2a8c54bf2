#pragma once
/// Small file helpers shared by the modules that read files, so that every reader reports a
/// missing or unreadable file the same way.
#include <filesystem>
#include <functional>
#include <cstdint>
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch {

/// "'path'", for messages.
std::string quoted(const std::filesystem::path& path);

/// OK when `path` is a regular file that can be opened for reading; otherwise kNotFound
/// ("'path': no such file"), or an error saying it is not a regular file or cannot be opened.
Status check_readable_file(const std::filesystem::path& path);

/// fsync of a file, or of a folder (so that a rename in it is on disk).
Status fsync_path(const std::filesystem::path& path, bool directory);

/// Writes `path` so that a crash leaves either the old file or the new one, never a part: creates
/// the parent folder, lets `write` fill a temporary file beside it (`path` + `tmp_suffix`; a
/// writer that picks its format by the extension needs it kept), fsyncs it, renames it into
/// place and fsyncs the folder. The temporary file is removed when `write` fails.
Status write_atomically(const std::filesystem::path& path,
                        const std::function<Status(const std::filesystem::path& tmp)>& write,
                        const std::string& tmp_suffix = ".tmp");

/// Runs `write` (a writer through a C++ stream or a C library: they leave errno as the failed
/// system call set it) with errno cleared; when it fails with errno set, the system's reason is
/// added to its message ("'a.ot': writing the map failed: No space left on device").
Status with_system_reason(const std::function<Status()>& write);

/// A regular file opened for reading beneath a directory: the kernel resolves the path at open
/// time (openat2 with RESOLVE_BENEATH), so no `..`, absolute symlink or symlink swapped in after a
/// check can lead outside it. Readers that take a path read it through `alias()`, a link with the
/// file's extension to /proc/self/fd/N in a private folder: the opened file, whatever the path
/// names by then. Closes and removes the alias on destruction.
class FileBeneath {
 public:
  FileBeneath(FileBeneath&& other) noexcept;
  FileBeneath& operator=(FileBeneath&&) = delete;
  FileBeneath(const FileBeneath&) = delete;
  ~FileBeneath();
  const std::filesystem::path& alias() const { return alias_; }
  std::uintmax_t size() const { return size_; }

 private:
  friend Result<FileBeneath> open_beneath(const std::filesystem::path&, const std::filesystem::path&);
  FileBeneath() = default;
  int fd_ = -1;
  std::uintmax_t size_ = 0;
  std::filesystem::path dir_, alias_;
};

/// Opens `relative` beneath `root`. kPermissionDenied when the path leaves the root (`..`, a
/// symlink out), kNotFound when it does not exist, kInvalidArgument when it is not a regular file.
Result<FileBeneath> open_beneath(const std::filesystem::path& root, const std::filesystem::path& relative);

}  // namespace scenewatch
