#pragma once
/// A small read-only HTTP/1.1 server for the live view: GET only, one request per connection
/// (then closed), a capped request head, a deadline for the head to arrive, and long-lived
/// streams for Server-Sent Events, with slots, a heartbeat and a timeout of their own. It knows nothing of perception: a handler maps each request to
/// a response (live_view.h). Boost.Asio stays inside its .cpp file.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/service/http_request.h"
#include "scenewatch/service/log.h"

namespace scenewatch::service {

/// The open end of a streaming response (text/event-stream). Thread safe.
class HttpStream {
 public:
  virtual ~HttpStream() = default;
  /// Queues bytes for the client; false once the stream is closed (client gone, too slow, server
  /// stopping), after which nothing more is sent.
  virtual bool send(std::string bytes) = 0;
  /// False once the stream is closed.
  virtual bool open() const = 0;
};

/// One response. With `on_stream` set, the connection stays open after the head (and `body`)
/// and on_stream is called once with its stream, before anything queued by it is sent; when
/// every stream slot is taken the client gets 503 instead, and on_stream is not called.
struct HttpResponse {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
  std::function<void(std::shared_ptr<HttpStream>)> on_stream;
  /// A stream's keep-alive: sent every HttpServerConfig::heartbeat_s when nothing else waits to
  /// be sent (for Server-Sent Events, a comment line). Empty: none.
  std::string heartbeat;
};

/// A plain-text error response ("404 Not Found\n" followed by the message).
HttpResponse http_error(int status, const std::string& message);
/// "Not Found" for 404, ...; "Unknown" for codes it does not know.
const char* http_reason(int status);

/// Maps a parsed GET request to a response; called on the server's thread (it may block a while,
/// delaying other requests, but must not wait for a client).
using HttpHandler = std::function<HttpResponse(const HttpRequest& request)>;

struct HttpServerConfig {
  std::string address = "127.0.0.1";    ///< loopback unless opened on purpose
  std::uint16_t port = 0;               ///< 0: pick a free port
  std::size_t max_head_bytes = 8192;    ///< a larger request head gets 413
  double head_timeout_s = 10.0;         ///< the head must arrive whole within this, else the connection closes
  std::size_t max_connections = 32;     ///< connections before their answer (page requests); further ones get 503
  std::size_t max_streams = 32;         ///< open streams, counted apart from requests; further ones get 503
  std::size_t max_stream_queue_bytes = 4u << 20;  ///< a stream whose client reads slower is closed
  double heartbeat_s = 15.0;            ///< an idle stream sends its response's heartbeat this often
  /// A stream whose queued bytes the client has not taken for this long is closed (and the
  /// kernel drops a peer that acknowledges nothing for as long: TCP_USER_TIMEOUT).
  double stream_timeout_s = 60.0;
};

/// Runs its own network thread: listen(), then start(); stop() (or the destructor) ends it.
/// listen() and start() are called from one thread; stop() is thread safe.
class HttpServer {
 public:
  HttpServer(HttpServerConfig config, HttpHandler handler, LogSink log = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Opens the listening socket; the message names address and port when that fails.
  Status listen();
  /// The bound port (the actual one when the configured port was 0); valid after listen().
  std::uint16_t port() const;
  /// "address:port"; valid after listen().
  std::string endpoint() const;
  /// Starts serving on a thread of its own.
  void start();
  /// Closes the listening socket and every connection (streams included), joins the thread.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::service
