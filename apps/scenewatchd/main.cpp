// scenewatchd: the scenewatch perception service. Serves the wire protocol (proto/scenewatch.proto)
// over TCP, keeps the working memory of the scene, and persists it in the model directory.
#include <CLI/CLI.hpp>

#include <sys/resource.h>

#include <chrono>
#include <csignal>
#include <ctime>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "install_layout.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/access_token.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/service/daemon_config.h"
#include "scenewatch/service/http_server.h"
#include "scenewatch/service/live_view.h"
#include "scenewatch/service/log.h"
#include "scenewatch/service/model_directory.h"
#include "scenewatch/service/server.h"
#include "scenewatch/core/memory.h"

namespace {

using scenewatch::service::LogLevel;

/// Thread-safe stderr logger: "2024-05-01T12:00:00.123Z INFO  message".
class StderrLog {
 public:
  explicit StderrLog(LogLevel min_level) : min_level_(min_level) {}

  void operator()(LogLevel level, const std::string& message) {
    if (static_cast<int>(level) < static_cast<int>(min_level_)) return;
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
    std::tm tm{};
    ::gmtime_r(&t, &tm);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
    char line_prefix[64];
    std::snprintf(line_prefix, sizeof line_prefix, "%s.%03dZ %-5s ", stamp, static_cast<int>(ms),
                  scenewatch::service::to_string(level));
    std::lock_guard<std::mutex> lock(mutex_);
    std::cerr << line_prefix << message << '\n' << std::flush;
  }

 private:
  LogLevel min_level_;
  std::mutex mutex_;
};

/// Raises the soft limit of open files to the hard one: every client holds a socket, and a burst
/// of newcomers (each answered, then closed) briefly holds more; at the usual soft limit of 1024,
/// accept() would fail while they go. Says so when even the hard limit is tight.
void raise_open_file_limit(const scenewatch::service::ServerConfig& server, StderrLog& log) {
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0) return;
  if (limit.rlim_cur < limit.rlim_max) {
    rlimit raised = limit;
    raised.rlim_cur = limit.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) limit = raised;
  }
  // Each counted client, each stream and page request of the live view, and as many again for
  // connections being turned away or closed to make room, plus the daemon's own files.
  const rlim_t wanted = 2 * (server.max_connections + server.http_max_streams + 32) + 64;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur < wanted) {
    log(LogLevel::kWarning, "open files limited to " + std::to_string(limit.rlim_cur) + ", below the " +
                                std::to_string(wanted) + " that server.max_connections " +
                                std::to_string(server.max_connections) + " can use in a burst (raise ulimit -n)");
  }
}

/// The command line: each option given overrides its key of the config file.
struct Options {
  std::string config_path;
  std::optional<int> port;
  std::optional<std::string> address;
  std::optional<std::string> model_dir;
  std::optional<std::string> token_file;
  std::optional<int> http_port;
  std::optional<std::string> http_bind;
  std::string log_level = "info";
};

/// Parses the command line into `options`; returns the exit code when the process should end
/// here (--help, --version, a bad option).
std::optional<int> parse_options(int argc, char** argv, Options& options) {
  CLI::App app{"scenewatchd - the scenewatch perception service.\n"
               "Serves the scenewatch protocol (4-byte big-endian length + protobuf) over TCP, keeps the\n"
               "working memory of the scene and saves it to the model directory on SaveModel and on\n"
               "SIGINT/SIGTERM. Prints 'listening on ADDRESS:PORT' on stdout once ready (and, with --http,\n"
               "'live view on http://ADDRESS:PORT/' on the next line)."};
  app.set_version_flag("--version", "scenewatchd " SCENEWATCH_VERSION);
  app.add_option("--config", options.config_path,
                 "YAML config file (see config/scenewatchd.yaml); default: an installed daemon's "
                 "scenewatchd.yaml (/etc/scenewatch/, or PREFIX/etc/scenewatch/), else built-in defaults");
  app.add_option("--port", options.port, "TCP port, 0 = pick a free one (overrides server.port)")->check(CLI::Range(0, 65535));
  app.add_option("--address", options.address, "listen address (overrides server.address)");
  app.add_option("--model-dir", options.model_dir, "model directory, '' = none (overrides server.model_dir)");
  app.add_option("--token-file", options.token_file,
                 "access token file, created (mode 0600) when missing (overrides server.token_file; "
                 "default ~/.scenewatch/token)");
  app.add_option("--http", options.http_port,
                 "serve the live view in the browser on this HTTP port, 0 = pick a free one (overrides "
                 "server.http_port; read-only)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--http-bind", options.http_bind,
                 "the live view's listen address (overrides server.http_bind; default 127.0.0.1)");
  app.add_option("--log-level", options.log_level, "debug, info, warn or error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

LogLevel log_level_named(const std::string& name) {
  return name == "debug"   ? LogLevel::kDebug
         : name == "warn"  ? LogLevel::kWarning
         : name == "error" ? LogLevel::kError
                           : LogLevel::kInfo;
}

/// The config file, the command line's overrides on top, validated. Logs why when there is none.
std::optional<scenewatch::service::DaemonConfig> load_config(Options options, StderrLog& log) {
  // An installed daemon reads the shipped config when given none; one run from the build tree
  // keeps the built-in defaults (the same values), as before it could be installed.
  const std::filesystem::path installed_config = scenewatch::apps::config_dir() / "scenewatchd.yaml";
  if (options.config_path.empty() && !scenewatch::apps::installed_prefix().empty()) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(installed_config, ec)) {
      options.config_path = installed_config.string();
    } else {
      log(LogLevel::kWarning, "config: no " + installed_config.string() + " (was it removed?); using the built-in defaults");
    }
  }
  scenewatch::service::DaemonConfig config;
  if (!options.config_path.empty()) {
    log(LogLevel::kInfo, "config: " + options.config_path);
    auto loaded = scenewatch::service::load_daemon_config(options.config_path);
    if (!loaded) {
      log(LogLevel::kError, "config: " + loaded.error().message);
      return std::nullopt;
    }
    config = std::move(*loaded);
  }
  if (options.port) config.server.port = static_cast<std::uint16_t>(*options.port);
  if (options.address) config.server.address = *options.address;
  if (options.model_dir) config.server.model_dir = *options.model_dir;
  if (options.token_file) config.server.token_file = *options.token_file;
  if (options.http_port) config.server.http_port = static_cast<std::uint16_t>(*options.http_port);
  if (options.http_bind) config.server.http_bind = *options.http_bind;
  if (config.server.token_file.empty()) config.server.token_file = scenewatch::service::default_token_path();
  if (auto s = scenewatch::service::validate(config.server); !s) {
    log(LogLevel::kError, "config: " + s.error().message);
    return std::nullopt;
  }
  if (auto s = scenewatch::pipeline::validate(config.pipeline); !s) {
    log(LogLevel::kError, "config: " + s.error().message);
    return std::nullopt;
  }
  return config;
}

/// Reads the access token that calls changing the model need (docs/daemon.md, "Access token").
bool read_access_token(scenewatch::service::ServerConfig& server, StderrLog& log) {
  auto token = scenewatch::service::ensure_token_file(server.token_file);
  if (!token) {
    log(LogLevel::kError, "access token: " + token.error().message);
    return false;
  }
  server.access_token = std::move(*token);
  log(LogLevel::kInfo, "calls that change the model need the token in " + server.token_file.string());
  return true;
}

/// Locks the model directory for this process's lifetime (one daemon per directory) and removes
/// what killed or failed saves left behind, before anything is loaded.
bool lock_model_dir(const std::filesystem::path& model, std::optional<scenewatch::service::ModelDirLock>& model_lock,
                    StderrLog& log) {
  auto locked = scenewatch::service::ModelDirLock::acquire(model);
  if (!locked) {
    log(LogLevel::kError, "model directory: " + locked.error().message);
    return false;
  }
  model_lock = std::move(*locked);
  for (const auto& name : scenewatch::service::remove_unfinished_snapshots(model)) {
    log(LogLevel::kWarning, "removed " + (model / name).string() + ", left behind by a save that did not finish");
  }
  return true;
}

/// Loads the newest good snapshot of the model directory into memory; none yet is an empty start.
bool load_model(scenewatch::pipeline::WorkingMemory& memory, const std::filesystem::path& model, StderrLog& log) {
  if (auto s = scenewatch::service::load_newest_good(memory, model); s) {
    for (const auto& refused : s->refused) log(LogLevel::kError, "refused a damaged snapshot: " + refused);
    log(s->refused.empty() ? LogLevel::kInfo : LogLevel::kWarning,
        "loaded the model from " + s->folder.string() + " (" + std::to_string(memory.snapshot()->objects.size()) +
            " objects)" + (s->refused.empty() ? "" : "; the newer snapshot stays on disk as it is, unused"));
  } else if (s.error().code == scenewatch::ErrorCode::kNotFound) {
    log(LogLevel::kInfo, "no model in " + model.string() + " yet; starting empty");
  } else {
    // Starting empty would overwrite the damaged model at exit: refuse instead.
    log(LogLevel::kError, "cannot load the model from " + model.string() + ": " + s.error().message +
                              " (repair or move the directory, or pass another --model-dir)");
    return false;
  }
  return true;
}

/// The object classes: the classes file, overlaid by those defined through DefineClass, which
/// ontology.sqlite in the model directory keeps.
bool open_classes(scenewatch::service::DaemonConfig& config, StderrLog& log) {
  const std::filesystem::path& model = config.server.model_dir;
  const std::filesystem::path classes_file =
      config.ontology.classes_file.empty() ? scenewatch::apps::config_dir() / "ontology.yaml" : config.ontology.classes_file;
  std::filesystem::path class_store;
  if (!model.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(model, ec);
    if (ec) {
      log(LogLevel::kError, "cannot create the model directory " + model.string() + ": " + ec.message());
      return false;
    }
    class_store = model / scenewatch::ontology::kClassStoreFile;
  }
  auto classes = scenewatch::ontology::ClassCatalog::open(classes_file, class_store);
  if (!classes) {
    log(LogLevel::kError, "ontology: " + classes.error().message);
    return false;
  }
  config.server.classes = std::move(*classes);
  log(LogLevel::kInfo, "object classes: " + std::to_string(config.server.classes->library().classes().size()) + " (" +
                           classes_file.string() + (class_store.empty() ? std::string(", not persisted)") : ", store " + class_store.string() + ")"));
  return true;
}

/// The live view in the browser: its own thread and socket; it sees the frames the server processes.
struct LiveViewServer {
  std::unique_ptr<scenewatch::service::LiveView> view;
  std::unique_ptr<scenewatch::service::HttpServer> http;
};

/// Starts listening for the live view (not yet serving); false when its port cannot be bound.
bool listen_live_view(const scenewatch::service::ServerConfig& server_config, scenewatch::pipeline::WorkingMemory& memory,
                      scenewatch::service::Server& server, StderrLog& log, LiveViewServer& live) {
  scenewatch::service::LiveViewConfig view_config;
  view_config.three_js = server_config.http_three_js;
  view_config.classes = server_config.classes;
  view_config.suggested_views = server_config.suggested_views;
  live.view = std::make_unique<scenewatch::service::LiveView>(memory, view_config);
  if (auto s = live.view->check_three_js(); !s) log(LogLevel::kWarning, "live view: " + s.error().message);
  server.set_frame_observer([view = live.view.get()](const scenewatch::Frame& frame,
                                                     const scenewatch::pipeline::FrameResult& result) {
    view->observe(frame, result);
  });
  scenewatch::service::HttpServerConfig http_config;
  http_config.address = server_config.http_bind;
  http_config.port = server_config.http_port;
  http_config.max_streams = server_config.http_max_streams;
  http_config.heartbeat_s = server_config.http_heartbeat_s;
  http_config.stream_timeout_s = server_config.http_stream_timeout_s;
  live.http = std::make_unique<scenewatch::service::HttpServer>(
      http_config, [view = live.view.get()](const scenewatch::service::HttpRequest& r) { return view->handle(r); },
      [&log](LogLevel level, const std::string& message) { log(level, message); });
  if (auto s = live.http->listen(); !s) {
    log(LogLevel::kError, "live view: " + s.error().message);
    return false;
  }
  return true;
}

/// Saves the model at exit; the process's exit code.
int save_at_exit(const scenewatch::pipeline::WorkingMemory& memory, const scenewatch::service::ServerConfig& server,
                 StderrLog& log) {
  int rc = 0;
  const std::filesystem::path& model = server.model_dir;
  if (!model.empty()) {
    if (auto s = scenewatch::service::save_model(memory, model, server.keep_snapshots); s) {
      log(LogLevel::kInfo, "saved the model to " + model.string());
    } else {
      log(LogLevel::kError, "cannot save the model to " + model.string() + ": " + s.error().message);
      rc = 1;
    }
  }
  log(LogLevel::kInfo, "stopped");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  scenewatch::keep_frame_buffers_in_heap();
  Options options;
  if (auto rc = parse_options(argc, argv, options)) return *rc;
  StderrLog log(log_level_named(options.log_level));
  std::signal(SIGPIPE, SIG_IGN);

  auto config = load_config(options, log);
  if (!config) return 1;
  // The live view is on when --http is given (0: a free port) or server.http_port is set.
  const bool live_view_on = options.http_port.has_value() || config->server.http_port != 0;
  if (!read_access_token(config->server, log)) return 1;
  raise_open_file_limit(config->server, log);

  scenewatch::pipeline::WorkingMemory memory(config->pipeline);
  const std::filesystem::path& model = config->server.model_dir;
  std::optional<scenewatch::service::ModelDirLock> model_lock;  // held until this process ends
  if (!model.empty()) {
    if (!lock_model_dir(model, model_lock, log) || !load_model(memory, model, log)) return 1;
  } else {
    log(LogLevel::kInfo, "no model directory configured: the model is not persisted");
  }
  if (!open_classes(*config, log)) return 1;

  scenewatch::service::Server server(config->server, memory,
                                     [&log](LogLevel level, const std::string& message) { log(level, message); });
  if (auto s = server.listen(); !s) {
    log(LogLevel::kError, s.error().message);
    return 1;
  }
  LiveViewServer live;
  if (live_view_on && !listen_live_view(config->server, memory, server, log, live)) return 1;

  log(LogLevel::kInfo, "scenewatchd listening on " + server.endpoint() + " (max message " +
                           std::to_string(config->server.max_message_bytes) + " bytes, " +
                           std::to_string(config->server.data_roots.size()) + " data roots)");
  std::cout << "listening on " << server.endpoint() << std::endl;
  if (live.http) {
    live.http->start();
    log(LogLevel::kInfo, "live view (read-only) on http://" + live.http->endpoint() + "/");
    std::cout << "live view on http://" << live.http->endpoint() << "/" << std::endl;
  }

  server.run();
  // No frame is processed any more: the live view's streams can close.
  if (live.http) live.http->stop();
  return save_at_exit(memory, config->server, log);
}
