#pragma once
/// The `server` section of scenewatchd's YAML configuration (see daemon_config.h for the file).
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/service/suggested_views.h"

namespace scenewatch::ontology {
class ClassCatalog;
}  // namespace scenewatch::ontology

namespace scenewatch::service {

/// The TCP port of scenewatchd unless configured otherwise (also the CLI's default).
inline constexpr std::uint16_t kDefaultPort = 7878;

/// The `server:` section. Defaults are those of config/scenewatchd.yaml.
struct ServerConfig {
  std::string address = "127.0.0.1";            ///< listen address; loopback unless opened on purpose
  std::uint16_t port = kDefaultPort;            ///< 0: pick a free port (the daemon prints it)
  std::size_t max_message_bytes = 64u << 20;    ///< largest accepted frame payload (64 MiB)
  double read_timeout_s = 10.0;                 ///< a frame stalled this long mid-way closes the connection
  double frame_timeout_s = 30.0;                ///< a frame not whole this long after its first byte closes it
  std::size_t max_queued_bytes = 16u << 20;     ///< outgoing bytes queued per client before a subscriber is dropped
  std::size_t max_buffered_bytes = 256u << 20;  ///< bytes of unfinished frames held across all clients
  std::size_t max_connections = 64;             ///< further clients get UNAVAILABLE and are closed
  int io_threads = 2;                           ///< threads running the sockets
  std::vector<std::filesystem::path> data_roots;  ///< IngestFile only reads below these (none: disabled)
  std::uint64_t max_file_bytes = 512ull << 20;  ///< larger files under the data roots are refused unread
  std::filesystem::path model_dir;              ///< loaded at start, saved by SaveModel and at exit (empty: none)
  std::size_t keep_snapshots = 3;               ///< saved models kept in model_dir (the newest is `current`)
  /// The access token's file, created at start when missing (empty: default_token_path()).
  std::filesystem::path token_file;
  /// The live view's HTTP port (0: no live view); read-only, so it needs no token.
  std::uint16_t http_port = 0;
  std::string http_bind = "127.0.0.1";          ///< the live view's listen address
  /// three.js for the page's 3D view (Debian's libjs-three).
  std::filesystem::path http_three_js = "/usr/share/javascript/three/three.min.js";
  std::size_t http_max_streams = 32;            ///< event streams open at once, apart from page requests
  double http_heartbeat_s = 15.0;               ///< an idle event stream carries a comment line this often
  double http_stream_timeout_s = 60.0;          ///< a stream whose client takes nothing this long is closed
  /// Not read from YAML: the token itself (the contents of token_file), which calls that change
  /// the model must carry. Server::listen() refuses to serve without one.
  std::string access_token;
  /// Not read from YAML: the object classes the daemon serves (DefineClass, ListClasses); null: none.
  std::shared_ptr<ontology::ClassCatalog> classes;
  /// Not read from YAML: where NextBestView answers are kept for the live view (both get this one).
  std::shared_ptr<SuggestedViews> suggested_views = std::make_shared<SuggestedViews>();
};

/// Checks ranges; the message names the key ("server.read_timeout_s: must be > 0, got 0").
Status validate(const ServerConfig& config);

/// Reads the `server` section of a parsed YAML root (absent: defaults). Unknown keys are errors.
/// Relative data_roots and model_dir are taken relative to `base_dir` (the config file's folder).
Status read_server_config(const YAML::Node& root, const std::filesystem::path& base_dir,
                          ServerConfig& config);

}  // namespace scenewatch::service
