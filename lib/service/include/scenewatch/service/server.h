#pragma once
/// The TCP server of scenewatchd: accepts clients, frames their messages and hands the payloads
/// to a RequestHandler. It knows nothing of perception; Boost.Asio stays inside its .cpp files.
#include <cstdint>
#include <memory>
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/service/log.h"
#include "scenewatch/service/request_handler.h"
#include "scenewatch/service/server_config.h"

namespace scenewatch::pipeline {
class WorkingMemory;
}  // namespace scenewatch::pipeline

namespace scenewatch::service {

/// Owns the acceptor, the sockets' io threads, a worker pool for the calls that touch the model,
/// and the registry of connections. `memory` must outlive the server. listen() and run() are
/// called from one thread; stop() is thread safe.
class Server {
 public:
  /// With `handle_signals`, SIGINT and SIGTERM (caught from listen() on) make run() return.
  Server(ServerConfig config, pipeline::WorkingMemory& memory, LogSink log = {}, bool handle_signals = true);
  /// Stops serving (if run() is still going, call stop() first) and joins the workers.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Opens the listening socket (and starts catching signals); the message names address and
  /// port when that fails.
  Status listen();

  /// The bound port (the actual one when the configured port was 0); valid after listen().
  std::uint16_t port() const;
  /// "address:port" of the listening socket ("[::1]:7878" for IPv6); valid after listen().
  std::string endpoint() const;

  /// Sees each frame an ingest call processed (the live view); set before run().
  void set_frame_observer(FrameObserver observer);

  /// Serves until stop() or a caught signal. Returns once every connection is closed and the
  /// calls in progress have finished.
  void run();

  /// Asks run() to return: stops accepting, closes connections, rejects queued model changes.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::service
