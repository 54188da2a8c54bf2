// Where the programs find their shipped files (config/, the simulator's scenarios): beside the
// installed program after `cmake --install` or the Debian package, else in the source tree the
// build came from. An installed program never looks at the source tree.
#pragma once

#include <filesystem>
#include <system_error>

namespace scenewatch::apps {

/// The install prefix when this program runs as `<prefix>/bin/NAME` of an install (one holds
/// `<prefix>/share/scenewatch`); empty when it runs from a build tree.
inline std::filesystem::path installed_prefix() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec || exe.parent_path().filename() != "bin") return {};
  const std::filesystem::path prefix = exe.parent_path().parent_path();
  if (!std::filesystem::is_directory(prefix / "share" / "scenewatch", ec)) return {};
  return prefix;
}

/// The shipped config folder: `/etc/scenewatch` for the prefixes `/usr` and `/` (where
/// GNUInstallDirs puts sysconfdir, and where the install rules put it), `<prefix>/etc/scenewatch`
/// for any other prefix, the source tree's `config/` when not installed.
inline std::filesystem::path config_dir() {
  const std::filesystem::path prefix = installed_prefix();
  if (prefix.empty()) return SCENEWATCH_SOURCE_CONFIG_DIR;
  if (prefix == "/usr" || prefix == "/") return "/etc/scenewatch";
  return prefix / "etc" / "scenewatch";
}

/// The simulator's shipped scenarios: `<prefix>/share/scenewatch/scenarios`, or the source tree's
/// `sample_clouds/scenarios` when not installed.
inline std::filesystem::path scenarios_dir() {
  const std::filesystem::path prefix = installed_prefix();
  if (prefix.empty()) return SCENEWATCH_SOURCE_SCENARIOS_DIR;
  return prefix / "share" / "scenewatch" / "scenarios";
}

}  // namespace scenewatch::apps
