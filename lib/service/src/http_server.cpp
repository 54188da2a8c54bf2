#include "scenewatch/service/http_server.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <exception>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "tcp_endpoint.h"

namespace scenewatch::service {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

const char* http_reason(int status) {
  switch (status) {
    case 200: return "OK";
    case 204: return "No Content";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 413: return "Payload Too Large";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    case 505: return "HTTP Version Not Supported";
    default: return "Unknown";
  }
}

HttpResponse http_error(int status, const std::string& message) {
  HttpResponse r;
  r.status = status;
  r.body = std::to_string(status) + " " + http_reason(status) + "\n" + message + "\n";
  return r;
}

namespace {

/// Seconds a connection keeps reading (and dropping) after its answer was sent.
constexpr int kLingerS = 2;

std::string response_head(const HttpResponse& r, bool streaming) {
  std::string head = "HTTP/1.1 " + std::to_string(r.status) + " " + http_reason(r.status) + "\r\n";
  head += "Content-Type: " + r.content_type + "\r\n";
  if (!streaming) head += "Content-Length: " + std::to_string(r.body.size()) + "\r\n";
  if (r.status == 405) head += "Allow: GET\r\n";
  head += "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n";
  return head;
}

class Connection;

/// The open connections, so that stop() can close them all: those before their answer (page
/// requests, up to max_connections) and the streams (up to max_streams) are counted apart, so
/// streams that stay open cannot take the slots page requests need. Thread safe.
class Registry {
 public:
  Registry(std::size_t max_requests, std::size_t max_streams) : max_requests_(max_requests), max_streams_(max_streams) {}
  enum class Added { kAdded, kFull, kStopping };
  /// Counts a new connection as a request; kFull (then it is only known to stop_all() until it
  /// closes) when max_requests are counted already.
  Added add(const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return Added::kStopping;
    if (requests_.size() >= max_requests_) {
      uncounted_.insert(c);
      return Added::kFull;
    }
    requests_.insert(c);
    return Added::kAdded;
  }
  /// Moves a request that is answered with a stream to the streams; false (it stays a request)
  /// when max_streams are open.
  bool become_stream(const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (streams_.size() >= max_streams_ || requests_.erase(c) == 0) return false;
    streams_.insert(c);
    return true;
  }
  void remove(const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    requests_.erase(c);
    streams_.erase(c);
    uncounted_.erase(c);
  }
  std::vector<std::shared_ptr<Connection>> stop_all() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    std::vector<std::shared_ptr<Connection>> all(requests_.begin(), requests_.end());
    all.insert(all.end(), streams_.begin(), streams_.end());
    all.insert(all.end(), uncounted_.begin(), uncounted_.end());
    requests_.clear();
    streams_.clear();
    uncounted_.clear();
    return all;
  }

 private:
  const std::size_t max_requests_, max_streams_;
  std::mutex mutex_;
  std::set<std::shared_ptr<Connection>> requests_, streams_, uncounted_;
  bool stopped_ = false;
};

struct Shared {
  Shared(HttpServerConfig c, HttpHandler h, LogSink l)
      : config(std::move(c)), handler(std::move(h)), log(std::move(l)), registry(config.max_connections, config.max_streams) {}
  HttpServerConfig config;
  HttpHandler handler;
  LogSink log;
  Registry registry;
  void write_log(LogLevel level, const std::string& message) const {
    if (log) log(level, message);
  }
};

/// One client: reads the head, answers, closes; or, for a stream, keeps writing what is sent to
/// it until the client goes or the server stops. Everything runs on the socket's strand.
class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(tcp::socket socket, Shared& shared)
      : socket_(std::move(socket)), timer_(socket_.get_executor()), shared_(shared),
        parser_(shared.config.max_head_bytes) {
    boost::system::error_code ec;
    const auto peer = socket_.remote_endpoint(ec);
    peer_ = ec ? std::string("unknown peer") : format_endpoint(peer);
  }

  void start() {
    timer_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(shared_.config.head_timeout_s)));
    timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec || self->answered_) return;
      self->shared_.write_log(LogLevel::kDebug, "http: " + self->peer_ + ": no whole request within " +
                                                    std::to_string(self->shared_.config.head_timeout_s) + " s");
      self->respond(http_error(408, "the request head did not arrive in time"));
    });
    read();
  }

  /// Answers without reading (server full).
  void reject(HttpResponse response) { respond(std::move(response)); }

  /// From any thread.
  void close_from_outside() {
    asio::post(socket_.get_executor(), [self = shared_from_this()] { self->close(); });
  }

  /// From any thread (through Stream).
  bool send(std::string bytes) {
    if (closed_.load()) return false;
    asio::post(socket_.get_executor(), [self = shared_from_this(), bytes = std::move(bytes)]() mutable {
      self->queue(std::move(bytes));
    });
    return true;
  }
  bool is_open() const { return !closed_.load(); }

 private:
  void read() {
    socket_.async_read_some(asio::buffer(buffer_), [self = shared_from_this()](const boost::system::error_code& ec,
                                                                               std::size_t n) {
      self->on_read(ec, n);
    });
  }

  void on_read(const boost::system::error_code& ec, std::size_t n) {
    if (closed_) return;
    if (ec) {
      // The client went away: before finishing its request, from its stream, or after its answer.
      if (!answered_ || streaming_ || lingering_) close();
      return;
    }
    if (answered_) {
      // What a client sends after its request does not matter: it is read only to notice its close.
      if (streaming_ || lingering_) read();
      return;
    }
    switch (parser_.feed(std::string_view(buffer_.data(), n))) {
      case HttpRequestParser::State::kIncomplete:
        read();
        return;
      case HttpRequestParser::State::kError:
        shared_.write_log(LogLevel::kDebug, "http: " + peer_ + ": " + std::to_string(parser_.error_status()) + " " +
                                                parser_.error());
        respond(http_error(parser_.error_status(), parser_.error()));
        return;
      case HttpRequestParser::State::kComplete:
        break;
    }
    const HttpRequest& request = parser_.request();
    if (request.method != "GET") {
      respond(http_error(405, "only GET is served: the live view is read-only"));
      return;
    }
    HttpResponse response;
    try {
      response = shared_.handler(request);
    } catch (const std::exception& e) {
      shared_.write_log(LogLevel::kError, "http: " + request.path + ": " + e.what());
      response = http_error(500, "internal error");
    }
    respond(std::move(response));
  }

  void respond(HttpResponse response) {
    if (answered_ || closed_) return;
    answered_ = true;
    timer_.cancel();
    if (response.on_stream && !shared_.registry.become_stream(shared_from_this())) {
      response = http_error(503, "too many event streams open (limit " + std::to_string(shared_.config.max_streams) +
                                     ", server.http_max_streams)");
    }
    streaming_ = static_cast<bool>(response.on_stream);
    queue(response_head(response, streaming_) + response.body);
    if (streaming_) {
      heartbeat_ = std::move(response.heartbeat);
      start_stream_clock();
      // Registered before the head leaves: anything the stream sends is queued after it.
      response.on_stream(std::make_shared<Stream>(shared_from_this()));
      read();  // to notice the client's close
    }
  }

  /// A stream's clock: every heartbeat_s, the heartbeat when nothing waits to be sent, and the
  /// end of a stream whose client has taken none of its bytes for stream_timeout_s. The kernel
  /// is told the same timeout for bytes it cannot deliver (a peer gone without a word).
  void start_stream_clock() {
    const unsigned timeout_ms = static_cast<unsigned>(shared_.config.stream_timeout_s * 1000);
    ::setsockopt(socket_.native_handle(), IPPROTO_TCP, TCP_USER_TIMEOUT, &timeout_ms, sizeof timeout_ms);
    last_progress_ = std::chrono::steady_clock::now();
    tick();
  }

  void tick() {
    timer_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(std::min(shared_.config.heartbeat_s, shared_.config.stream_timeout_s))));
    timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec || self->closed_) return;
      const double stalled_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - self->last_progress_).count();
      if (!self->queue_.empty() && stalled_s >= self->shared_.config.stream_timeout_s) {
        self->shared_.write_log(LogLevel::kWarning, "http: " + self->peer_ + ": stream closed, the client has taken "
                                                    "nothing for " + std::to_string(stalled_s) +
                                                    " s (server.http_stream_timeout_s)");
        self->close();
        return;
      }
      if (self->queue_.empty() && !self->heartbeat_.empty()) self->queue(self->heartbeat_);
      self->tick();
    });
  }

  void queue(std::string bytes) {
    if (closed_) return;
    if (queue_.empty()) last_progress_ = std::chrono::steady_clock::now();
    queued_bytes_ += bytes.size();
    if (streaming_ && queued_bytes_ > shared_.config.max_stream_queue_bytes) {
      shared_.write_log(LogLevel::kWarning, "http: " + peer_ + ": stream closed, the client reads too slowly");
      close();
      return;
    }
    queue_.push_back(std::move(bytes));
    if (queue_.size() == 1) write_next();
  }

  void write_next() {
    asio::async_write(socket_, asio::buffer(queue_.front()),
                      [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                        if (self->closed_) return;
                        if (ec) {
                          self->close();
                          return;
                        }
                        self->queued_bytes_ -= self->queue_.front().size();
                        self->queue_.pop_front();
                        self->last_progress_ = std::chrono::steady_clock::now();
                        if (!self->queue_.empty()) {
                          self->write_next();
                        } else if (!self->streaming_) {
                          self->linger();  // one request per connection
                        }
                      });
  }

  /// After the answer: no more sending, and what the client still sends is read and dropped
  /// until it closes (at most kLingerS), so that closing with unread bytes (the rest of an
  /// oversized request) does not reset the connection before the client has read the answer.
  void linger() {
    lingering_ = true;
    boost::system::error_code ignored;
    socket_.shutdown(tcp::socket::shutdown_send, ignored);
    timer_.expires_after(std::chrono::seconds(kLingerS));
    timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->close();
    });
    read();
  }

  void close() {
    if (closed_.exchange(true)) return;
    boost::system::error_code ignored;
    timer_.cancel();
    socket_.shutdown(tcp::socket::shutdown_both, ignored);
    socket_.close(ignored);
    queue_.clear();
    shared_.registry.remove(shared_from_this());
  }

  /// The stream handed to the handler: holds the connection weakly, so a registered stream does
  /// not keep a closed connection alive.
  class Stream : public HttpStream {
   public:
    explicit Stream(const std::shared_ptr<Connection>& c) : connection_(c) {}
    bool send(std::string bytes) override {
      auto c = connection_.lock();
      return c && c->send(std::move(bytes));
    }
    bool open() const override {
      auto c = connection_.lock();
      return c && c->is_open();
    }

   private:
    std::weak_ptr<Connection> connection_;
  };

  tcp::socket socket_;
  asio::steady_timer timer_;
  Shared& shared_;
  HttpRequestParser parser_;
  std::array<char, 4096> buffer_{};
  std::string peer_;
  std::deque<std::string> queue_;
  std::size_t queued_bytes_ = 0;
  std::string heartbeat_;  ///< a stream's keep-alive bytes
  /// When the client last took bytes (a write completed), or the queue last became non-empty.
  std::chrono::steady_clock::time_point last_progress_;
  bool answered_ = false;
  bool streaming_ = false;
  bool lingering_ = false;
  std::atomic<bool> closed_{false};
};

}  // namespace

struct HttpServer::Impl {
  Impl(HttpServerConfig config, HttpHandler handler, LogSink log)
      : shared(std::move(config), std::move(handler), std::move(log)) {}
  Shared shared;
  asio::io_context io;
  tcp::acceptor acceptor{io};
  asio::steady_timer accept_retry{io};
  std::thread thread;
  std::atomic<bool> stopped{false};

  void do_accept() {
    acceptor.async_accept(asio::make_strand(io), [this](const boost::system::error_code& ec, tcp::socket socket) {
      if (ec) {
        if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
        shared.write_log(LogLevel::kError, "http: accept failed: " + ec.message());
        accept_retry.expires_after(std::chrono::milliseconds(100));
        accept_retry.async_wait([this](const boost::system::error_code& wait_ec) {
          if (!wait_ec && acceptor.is_open()) do_accept();
        });
        return;
      }
      auto connection = std::make_shared<Connection>(std::move(socket), shared);
      switch (shared.registry.add(connection)) {
        case Registry::Added::kStopping:
          return;
        case Registry::Added::kFull:
          connection->reject(http_error(503, "too many connections (limit " +
                                            std::to_string(shared.config.max_connections) + ")"));
          break;
        case Registry::Added::kAdded:
          connection->start();
          break;
      }
      do_accept();
    });
  }
};

HttpServer::HttpServer(HttpServerConfig config, HttpHandler handler, LogSink log)
    : impl_(std::make_unique<Impl>(std::move(config), std::move(handler), std::move(log))) {}

HttpServer::~HttpServer() { stop(); }

Status HttpServer::listen() {
  Impl& s = *impl_;
  if (auto listening = listen_on(s.acceptor, s.shared.config.address, s.shared.config.port, "server.http_bind",
                                 "for HTTP ");
      !listening) {
    return listening;
  }
  return {};
}

std::uint16_t HttpServer::port() const { return bound_port(impl_->acceptor); }

std::string HttpServer::endpoint() const { return bound_endpoint(impl_->acceptor); }

void HttpServer::start() {
  Impl& s = *impl_;
  if (s.thread.joinable() || !s.acceptor.is_open()) return;
  s.do_accept();
  s.thread = std::thread([&s] {
    // A handler that throws (out of memory, a bug) must not take the daemon down.
    for (;;) {
      try {
        s.io.run();
        return;
      } catch (const std::exception& e) {
        s.shared.write_log(LogLevel::kError, std::string("http: unexpected exception: ") + e.what());
      }
    }
  });
}

void HttpServer::stop() {
  Impl& s = *impl_;
  if (s.stopped.exchange(true)) return;
  asio::post(s.io, [&s] {
    boost::system::error_code ignored;
    s.acceptor.close(ignored);
    s.accept_retry.cancel();
    for (const auto& c : s.shared.registry.stop_all()) c->close_from_outside();
  });
  if (s.thread.joinable()) s.thread.join();
}

}  // namespace scenewatch::service
