#pragma once
/// Small file helpers shared by the modules that read files, so that every reader reports a
/// missing or unreadable file the same way.
#include <filesystem>
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch {

/// "'path'", for messages.
std::string quoted(const std::filesystem::path& path);

/// OK when `path` is a regular file that can be opened for reading; otherwise kNotFound
/// ("'path': no such file"), or an error saying it is not a regular file or cannot be opened.
Status check_readable_file(const std::filesystem::path& path);

}  // namespace scenewatch
