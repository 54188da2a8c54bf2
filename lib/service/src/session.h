#pragma once
// One client connection: reads frames, runs their requests one at a time in order, writes the
// replies and pushed events. Everything runs on the socket's strand.
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <chrono>
#include <optional>
#include <string>

#include "connection_registry.h"
#include "scenewatch/service/frame_parser.h"
#include "scenewatch/service/log.h"
#include "scenewatch/service/request_handler.h"
#include "tcp_endpoint.h"

namespace scenewatch::service {

struct SessionOptions {
  std::size_t max_message_bytes = 0;
  double read_timeout_s = 10.0;
  std::size_t max_queued_bytes = 0;
  double frame_timeout_s = 30.0;  ///< a frame must arrive whole within this from its first byte
  /// Memory for the unfinished frames of all sessions together (null: no limit but max_message_bytes).
  std::shared_ptr<FrameBudget> frame_budget;
};

/// Owned by shared_ptrs (the registry, pending operations, queued replies). The socket's
/// executor must be a strand; every member function except stop() runs on it.
class Session : public std::enable_shared_from_this<Session> {
 public:
  using Executor = boost::asio::ip::tcp::socket::executor_type;

  Session(boost::asio::ip::tcp::socket socket, const SessionOptions& options, RequestHandler& handler,
          ConnectionRegistry& registry, const LogSink& log, std::uint64_t number);
  ~Session();

  /// Starts reading. Call once, after adding the session to the registry.
  void start();
  /// Sends a connection-level error, then closes (e.g. too many connections).
  void start_rejected(ErrorCode code, const std::string& message);
  /// Closes the connection. Thread safe.
  void stop();
  /// Since when (steady clock, ns) the connection has been quiet: nothing asked, nothing being
  /// answered or sent, no unfinished frame, no subscription; a new connection is quiet from its
  /// accept. Negative while it is not, or once it was claimed for eviction. Thread safe.
  std::int64_t quiet_since_ns() const { return quiet_since_ns_.load(); }
  /// Claims a quiet connection for eviction: true when it was quiet, and from then on it stays
  /// out of use (bytes it sends are not read as requests) until evict() closes it; false when it
  /// was busy or claimed already. Thread safe; the ConnectionRegistry calls it under its lock.
  bool claim_for_eviction();
  /// Closes a connection claimed for eviction, telling the client `reason`. Thread safe.
  void evict(std::string reason);
  /// The strand the session runs on.
  const Executor& executor() const { return executor_; }

 private:
  /// A frame ready to send: its 4-byte length prefix and the payload.
  struct Outgoing {
    std::array<unsigned char, kFrameHeaderBytes> header;
    std::string payload;
  };

  void do_read();
  void on_read(const boost::system::error_code& ec, std::size_t n);
  void maybe_resume_reading();
  void resume_reading();
  void update_quiet();
  /// The connection is in use from now on (bytes arrived); false when it was claimed for
  /// eviction first.
  bool leave_quiet();
  /// No request waiting or running and nothing left to send.
  bool idle() const;
  void dispatch_next();
  /// Answers the live frames that a newer waiting live frame supersedes (see IngestFrame.live).
  void skip_superseded_live_frames();
  void on_reply(std::uint64_t sequence, Reply reply);
  /// Sends the reply of the request started as `sequence` once those started before it are sent.
  void answer(std::uint64_t sequence, Reply reply);
  void send_reply(Reply reply);
  void push_event(std::string payload);
  void enqueue(std::string payload);
  void do_write();
  void on_write(const boost::system::error_code& ec);
  void arm_timer(double seconds, void (Session::*on_expiry)());
  void cancel_timer();
  void on_stall_timeout();
  void on_linger_timeout();
  void fail_and_close(ErrorCode code, const std::string& message);
  void begin_linger();
  void close(const std::string& reason);
  void log(LogLevel level, const std::string& message) const;

  Executor executor_;  ///< the strand; copied once so other threads may post to it
  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer timer_;
  SessionOptions options_;
  RequestHandler& handler_;
  ConnectionRegistry& registry_;
  const LogSink& log_;
  std::uint64_t number_;
  std::string peer_;

  FrameParser parser_;
  /// When the unfinished frame began: each byte restarts the stall clock, not this one.
  std::optional<std::chrono::steady_clock::time_point> frame_started_;
  std::array<char, 64 * 1024> read_buffer_{};
  bool reading_ = false;        ///< a read is outstanding
  std::deque<std::string> pending_;  ///< requests received, not yet started
  std::size_t pending_bytes_ = 0;    ///< payload bytes in pending_
  /// Requests being handled: one, or two frames in a row (the next frame is decoded while the
  /// one before it is processed; see dispatch_next()).
  std::size_t in_flight_ = 0;
  bool frame_in_flight_ = false;     ///< the last request started is an IngestFrame, not live
  std::uint64_t next_started_ = 0;   ///< sequence number of the next request started
  std::uint64_t next_answered_ = 0;  ///< sequence number of the next reply to send
  std::map<std::uint64_t, Reply> early_replies_;  ///< replies that overtook one started before them
  std::deque<Outgoing> outgoing_;
  std::size_t queued_bytes_ = 0;
  bool writing_ = false;
  SessionContext context_;
  std::uint64_t timer_generation_ = 0;

  bool peer_done_ = false;      ///< the client half-closed: finish its requests, then close
  bool closing_ = false;        ///< no more requests: flush the error reply, then close
  bool lingering_ = false;      ///< our side is shut down; draining the client's bytes
  bool closed_ = false;
  std::string close_reason_;
  std::atomic<std::int64_t> quiet_since_ns_;
  bool held_large_frame_ = false;  ///< a frame of kLargeFrameBytes or more arrived since the last trim
  /// Drops the unfinished frame (its mapping and its booking); trims the heap when a large frame
  /// arrived.
  void release_frame_memory();
};

}  // namespace scenewatch::service
