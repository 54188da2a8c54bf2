#include "scenewatch/service/server_config.h"

#include "scenewatch/service/daemon_config.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "scenewatch/pipeline/config_loader.h"
#include "scenewatch/service/frame_parser.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMinMessageBytes = 1024;
constexpr std::size_t kMinQueuedBytes = 64 * 1024;
constexpr int kMaxIoThreads = 64;
constexpr double kMinHeartbeatS = 0.1, kMaxHeartbeatS = 3600;
constexpr double kMinStreamTimeoutS = 1, kMaxStreamTimeoutS = 86400;
constexpr long long kMaxHttpStreams = 1024;

template <typename T>
std::string str(const T& value) {
  std::ostringstream os;
  os << value;
  return os.str();
}

/// Reads an integer key and checks it lies in [lo, hi].
template <typename Out>
Status read_integer(pipeline::YamlSection& section, const std::string& key, long long lo, long long hi, Out& out) {
  long long value = static_cast<long long>(out);
  if (Status s = section.read(key, value); !s) return s;
  if (value < lo || value > hi) {
    return invalid_argument(section.path(key) + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                            "], got " + std::to_string(value));
  }
  out = static_cast<Out>(value);
  return {};
}

fs::path resolve(const fs::path& base_dir, const std::string& value) {
  const fs::path p(value);
  return p.is_absolute() || base_dir.empty() ? p : (base_dir / p).lexically_normal();
}

}  // namespace

Status validate(const ServerConfig& config) {
  if (config.address.empty()) return invalid_argument("server.address: must not be empty");
  if (config.max_message_bytes < kMinMessageBytes || config.max_message_bytes > kMaxEncodableFrameBytes) {
    return invalid_argument("server.max_message_bytes: must be in [" + std::to_string(kMinMessageBytes) + ", " +
                            std::to_string(kMaxEncodableFrameBytes) + "], got " +
                            std::to_string(config.max_message_bytes));
  }
  if (config.max_buffered_bytes < config.max_message_bytes) {
    return invalid_argument("server.max_buffered_bytes: must be >= max_message_bytes (" +
                            std::to_string(config.max_message_bytes) + "), got " + std::to_string(config.max_buffered_bytes));
  }
  if (!std::isfinite(config.frame_timeout_s) || config.frame_timeout_s <= 0) {
    return invalid_argument("server.frame_timeout_s: must be > 0, got " + str(config.frame_timeout_s));
  }
  if (!std::isfinite(config.read_timeout_s) || config.read_timeout_s <= 0) {
    return invalid_argument("server.read_timeout_s: must be > 0, got " + str(config.read_timeout_s));
  }
  if (config.max_queued_bytes < kMinQueuedBytes) {
    return invalid_argument("server.max_queued_bytes: must be >= " + std::to_string(kMinQueuedBytes) + ", got " +
                            std::to_string(config.max_queued_bytes));
  }
  if (config.max_connections < 1) return invalid_argument("server.max_connections: must be >= 1, got 0");
  if (config.io_threads < 1 || config.io_threads > kMaxIoThreads) {
    return invalid_argument("server.io_threads: must be in [1, " + std::to_string(kMaxIoThreads) + "], got " +
                            std::to_string(config.io_threads));
  }
  if (config.http_port != 0 && config.http_bind.empty()) {
    return invalid_argument("server.http_bind: must not be empty when server.http_port is set");
  }
  if (config.http_port != 0 && config.http_port == config.port) {
    return invalid_argument("server.http_port: must differ from server.port (" + std::to_string(config.port) + ")");
  }
  if (!std::isfinite(config.http_heartbeat_s) || config.http_heartbeat_s < kMinHeartbeatS ||
      config.http_heartbeat_s > kMaxHeartbeatS) {
    return invalid_argument("server.http_heartbeat_s: must be in [" + str(kMinHeartbeatS) + ", " + str(kMaxHeartbeatS) +
                            "] s, got " + str(config.http_heartbeat_s));
  }
  if (!std::isfinite(config.http_stream_timeout_s) || config.http_stream_timeout_s < kMinStreamTimeoutS ||
      config.http_stream_timeout_s > kMaxStreamTimeoutS) {
    return invalid_argument("server.http_stream_timeout_s: must be in [" + str(kMinStreamTimeoutS) + ", " +
                            str(kMaxStreamTimeoutS) + "] s, got " + str(config.http_stream_timeout_s));
  }
  for (std::size_t i = 0; i < config.data_roots.size(); ++i) {
    const fs::path& root = config.data_roots[i];
    std::error_code ec;
    if (root.empty() || !fs::is_directory(root, ec)) {
      return invalid_argument("server.data_roots[" + std::to_string(i) + "]: '" + root.string() +
                              "' is not an existing directory");
    }
  }
  return {};
}

Status read_server_config(const YAML::Node& root, const fs::path& base_dir, ServerConfig& config) {
  pipeline::YamlSection section(root["server"], "server");
  if (Status s = section.check_is_map(); !s) return s;
  if (Status s = section.read("address", config.address); !s) return s;
  if (Status s = read_integer(section, "port", 0, 65535, config.port); !s) return s;
  if (Status s = read_integer(section, "max_message_bytes", 1, std::numeric_limits<long long>::max(),
                              config.max_message_bytes);
      !s) {
    return s;
  }
  if (Status s = section.read("read_timeout_s", config.read_timeout_s); !s) return s;
  if (Status s = section.read("frame_timeout_s", config.frame_timeout_s); !s) return s;
  if (Status s = read_integer(section, "max_queued_bytes", 1, std::numeric_limits<long long>::max(),
                              config.max_queued_bytes);
      !s) {
    return s;
  }
  if (Status s = read_integer(section, "max_connections", 1, 100000, config.max_connections); !s) return s;
  if (Status s = read_integer(section, "max_buffered_bytes", 1, std::numeric_limits<long long>::max(),
                              config.max_buffered_bytes);
      !s) {
    return s;
  }
  if (Status s = read_integer(section, "max_file_bytes", 1, std::numeric_limits<long long>::max(), config.max_file_bytes);
      !s) {
    return s;
  }
  if (Status s = read_integer(section, "io_threads", 1, kMaxIoThreads, config.io_threads); !s) return s;
  if (Status s = read_integer(section, "keep_snapshots", 1, 1000, config.keep_snapshots); !s) return s;

  if (Status s = read_integer(section, "http_port", 0, 65535, config.http_port); !s) return s;
  if (Status s = section.read("http_bind", config.http_bind); !s) return s;
  if (Status s = read_integer(section, "http_max_streams", 1, kMaxHttpStreams, config.http_max_streams); !s) return s;
  if (Status s = section.read("http_heartbeat_s", config.http_heartbeat_s); !s) return s;
  if (Status s = section.read("http_stream_timeout_s", config.http_stream_timeout_s); !s) return s;
  std::string three_js = config.http_three_js.string();
  if (Status s = section.read("http_three_js", three_js); !s) return s;
  config.http_three_js = resolve(base_dir, three_js);

  std::vector<std::string> roots;
  for (const auto& r : config.data_roots) roots.push_back(r.string());
  if (Status s = section.read("data_roots", roots); !s) return s;
  config.data_roots.clear();
  for (const auto& r : roots) config.data_roots.push_back(resolve(base_dir, r));

  std::string token_file = config.token_file.string();
  if (Status s = section.read("token_file", token_file); !s) return s;
  config.token_file = token_file.empty() ? fs::path() : resolve(base_dir, token_file);

  std::string model_dir = config.model_dir.string();
  if (Status s = section.read("model_dir", model_dir); !s) return s;
  config.model_dir = model_dir.empty() ? fs::path() : resolve(base_dir, model_dir);
  return section.finish();
}

Result<DaemonConfig> load_daemon_config(const fs::path& path) {
  std::vector<std::string> sections = pipeline::pipeline_sections();
  sections.push_back("server");
  sections.push_back("ontology");
  auto root = pipeline::load_yaml_file(path, sections);
  if (!root) return root.error();
  DaemonConfig config;
  const fs::path base_dir = fs::absolute(path).parent_path();
  if (Status s = read_server_config(*root, base_dir, config.server); !s) {
    return Error{s.error().code, path.string() + ": " + s.error().message};
  }
  if (Status s = validate(config.server); !s) return Error{s.error().code, path.string() + ": " + s.error().message};
  if (Status s = pipeline::read_pipeline_config(*root, config.pipeline); !s) {
    return Error{s.error().code, path.string() + ": " + s.error().message};
  }
  const YAML::Node& parsed = *root;
  pipeline::YamlSection ontology(parsed["ontology"], "ontology");
  std::string classes_file;
  Status s = ontology.check_is_map();
  if (s) s = ontology.read("classes_file", classes_file);
  if (s) s = ontology.finish();
  if (!s) return Error{s.error().code, path.string() + ": " + s.error().message};
  if (!classes_file.empty()) config.ontology.classes_file = resolve(base_dir, classes_file);
  return config;
}

}  // namespace scenewatch::service
