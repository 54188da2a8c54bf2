#include "scenewatch/service/http_server.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <exception>
#include <mutex>
#include <set>
#include <thread>

#include "session.h"  // format_endpoint

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

/// The open connections, so that stop() can close them all. Thread safe.
class Registry {
 public:
  /// False when stopping or full (the connection is then answered and closed by the caller).
  std::size_t add(const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return 0;
    connections_.insert(c);
    return connections_.size();
  }
  void remove(const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    connections_.erase(c);
  }
  std::set<std::shared_ptr<Connection>> stop_all() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    return std::exchange(connections_, {});
  }

 private:
  std::mutex mutex_;
  std::set<std::shared_ptr<Connection>> connections_;
  bool stopped_ = false;
};

struct Shared {
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
    streaming_ = static_cast<bool>(response.on_stream);
    queue(response_head(response, streaming_) + response.body);
    if (streaming_) {
      // Registered before the head leaves: anything the stream sends is queued after it.
      response.on_stream(std::make_shared<Stream>(shared_from_this()));
      read();  // to notice the client's close
    }
  }

  void queue(std::string bytes) {
    if (closed_) return;
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
  bool answered_ = false;
  bool streaming_ = false;
  bool lingering_ = false;
  std::atomic<bool> closed_{false};
};

}  // namespace

struct HttpServer::Impl {
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
      const std::size_t count = shared.registry.add(connection);
      if (count == 0) return;  // stopping
      if (count > shared.config.max_connections) {
        connection->reject(http_error(503, "too many connections (limit " +
                                          std::to_string(shared.config.max_connections) + ")"));
      } else {
        connection->start();
      }
      do_accept();
    });
  }
};

HttpServer::HttpServer(HttpServerConfig config, HttpHandler handler, LogSink log) : impl_(std::make_unique<Impl>()) {
  impl_->shared.config = std::move(config);
  impl_->shared.handler = std::move(handler);
  impl_->shared.log = std::move(log);
}

HttpServer::~HttpServer() { stop(); }

Status HttpServer::listen() {
  Impl& s = *impl_;
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(s.shared.config.address, ec);
  if (ec) return invalid_argument("server.http_bind: '" + s.shared.config.address + "' is not an IP address");
  const tcp::endpoint endpoint(address, s.shared.config.port);
  s.acceptor.open(endpoint.protocol(), ec);
  if (!ec) s.acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(endpoint, ec);
  if (!ec) s.acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    boost::system::error_code ignored;
    s.acceptor.close(ignored);
    return io_error("cannot listen for HTTP on " + format_endpoint(endpoint) + ": " + ec.message());
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
