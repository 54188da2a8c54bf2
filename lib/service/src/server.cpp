#include "scenewatch/service/server.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>

#include <atomic>
#include <csignal>
#include <exception>
#include <thread>
#include <vector>

#include "connection_registry.h"
#include "scenewatch/service/request_handler.h"
#include "session.h"

namespace scenewatch::service {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {
/// Worker threads for calls that touch the model: one runs model changes (a strand keeps them
/// in order), the other lets queries that wait for the map proceed meanwhile.
constexpr int kWorkerThreads = 2;
}  // namespace

struct Server::Impl {
  ServerConfig config;
  pipeline::WorkingMemory& memory;
  LogSink log;

  // Declaration order is destruction order in reverse: sessions (owned by the io_context's
  // handlers and the registry) go before the handler they unsubscribe from.
  asio::thread_pool workers{kWorkerThreads};
  asio::strand<asio::thread_pool::executor_type> model_strand{workers.get_executor()};
  RequestHandler handler;
  asio::io_context io;
  ConnectionRegistry registry;
  tcp::acceptor acceptor{io};
  asio::signal_set signals{io};
  // Memory reserved for the unfinished frames of all sessions (server.max_buffered_bytes).
  std::shared_ptr<FrameBudget> frame_budget = std::make_shared<FrameBudget>(config.max_buffered_bytes);
  asio::steady_timer accept_retry{io};
  std::atomic<std::uint64_t> next_number{1};
  std::atomic<bool> stop_requested{false};
  bool handle_signals = true;
  bool joined = false;

  Impl(ServerConfig c, pipeline::WorkingMemory& m, LogSink l, bool signals_wanted)
      : config(std::move(c)),
        memory(m),
        log(std::move(l)),
        handler(m, HandlerConfig{config.data_roots, config.model_dir, config.max_file_bytes, config.keep_snapshots,
                                    config.access_token, config.classes, config.suggested_views},
                [this](std::function<void()> task) { asio::post(model_strand, std::move(task)); },
                [this](std::function<void()> task) { asio::post(workers, std::move(task)); }) {
    handler.set_connection_counter([this] { return registry.size(); });
    handle_signals = signals_wanted;
  }

  ~Impl() {
    handler.shutdown();
    if (!joined) workers.join();
  }

  void write_log(LogLevel level, const std::string& message) const {
    if (log) log(level, message);
  }

  void do_accept() {
    acceptor.async_accept(asio::make_strand(io), [this](const boost::system::error_code& ec, tcp::socket socket) {
      if (ec) {
        if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
        // Typically out of file descriptors: wait a little instead of spinning.
        write_log(LogLevel::kError, "accept failed: " + ec.message());
        accept_retry.expires_after(std::chrono::milliseconds(100));
        accept_retry.async_wait([this](const boost::system::error_code& wait_ec) {
          if (!wait_ec && acceptor.is_open()) do_accept();
        });
        return;
      }
      on_accept(std::move(socket));
      do_accept();
    });
  }

  void on_accept(tcp::socket socket) {
    boost::system::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);
    const SessionOptions options{config.max_message_bytes, config.read_timeout_s, config.max_queued_bytes,
                                 config.frame_timeout_s, frame_budget};
    auto session = std::make_shared<Session>(std::move(socket), options, handler, registry, log, next_number++);
    // At the limit, the connection quiet for longest makes room (idle clients cannot lock others
    // out); only when every connection is busy or subscribed is the newcomer turned away.
    const Admission admission = registry.admit(session, config.max_connections);
    const std::string limit = "server.max_connections " + std::to_string(config.max_connections);
    switch (admission.kind) {
      case Admission::Kind::kStopping:
        return;  // the socket closes with the session
      case Admission::Kind::kRefused:
        asio::post(session->executor(), [session, limit] {
          session->start_rejected(ErrorCode::kUnavailable, "too many connections (" + limit + ")");
        });
        return;
      case Admission::Kind::kAdmitted:
        if (admission.evicted) {
          admission.evicted->evict("closed to make room for a new connection: this one was the quietest (" + limit + ")");
        }
        asio::post(session->executor(), [session] { session->start(); });
        return;
    }
  }

  void run_io() {
    // A handler that throws (out of memory, a bug) must not take the daemon down.
    for (;;) {
      try {
        io.run();
        return;
      } catch (const std::exception& e) {
        write_log(LogLevel::kError, std::string("unexpected exception in the network loop: ") + e.what());
      }
    }
  }
};

Server::Server(ServerConfig config, pipeline::WorkingMemory& memory, LogSink log, bool handle_signals)
    : impl_(std::make_unique<Impl>(std::move(config), memory, std::move(log), handle_signals)) {}

Server::~Server() = default;

Status Server::listen() {
  Impl& s = *impl_;
  if (s.config.access_token.empty()) {
    return invalid_argument("no access token: calls that change the model would be open to every local user "
                            "(read server.token_file into ServerConfig::access_token)");
  }
  if (auto listening = listen_on(s.acceptor, s.config.address, s.config.port, "server.address", ""); !listening) {
    return listening;
  }
  boost::system::error_code ec;
  if (s.handle_signals) {
    // Caught from here on (delivered once run() runs), so a signal right after the daemon says
    // it is listening still shuts it down cleanly.
    s.signals.add(SIGINT, ec);
    if (!ec) s.signals.add(SIGTERM, ec);
    if (ec) return io_error("cannot install the SIGINT/SIGTERM handler: " + ec.message());
    s.signals.async_wait([this](const boost::system::error_code& wait_ec, int signal) {
      if (wait_ec) return;
      impl_->write_log(LogLevel::kInfo, std::string("received ") + (signal == SIGINT ? "SIGINT" : "SIGTERM") +
                                            ", shutting down");
      stop();
    });
  }
  return {};
}

std::uint16_t Server::port() const { return bound_port(impl_->acceptor); }

std::string Server::endpoint() const { return bound_endpoint(impl_->acceptor); }

void Server::set_frame_observer(FrameObserver observer) { impl_->handler.set_frame_observer(std::move(observer)); }

void Server::run() {
  Impl& s = *impl_;
  if (s.stop_requested || !s.acceptor.is_open()) return;
  s.do_accept();
  std::vector<std::thread> threads;
  for (int i = 1; i < s.config.io_threads; ++i) threads.emplace_back([&s] { s.run_io(); });
  s.run_io();
  for (auto& thread : threads) thread.join();
  // Every connection is closed. Let the calls in progress finish (queued model changes are
  // answered UNAVAILABLE), then deliver their replies to the closed sessions, which drop them.
  s.handler.shutdown();
  s.workers.join();
  s.joined = true;
  s.io.restart();
  s.run_io();
}

void Server::stop() {
  Impl& s = *impl_;
  s.stop_requested = true;
  asio::post(s.io, [&s] {
    boost::system::error_code ignored;
    s.handler.shutdown();
    s.acceptor.close(ignored);
    s.accept_retry.cancel();
    s.signals.cancel(ignored);
    s.registry.stop_all();
  });
}

}  // namespace scenewatch::service
