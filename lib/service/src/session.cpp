#include "session.h"

#include <algorithm>
#include <atomic>

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include <chrono>
#include <sstream>
#include <utility>

#include "scenewatch/core/memory.h"

namespace scenewatch::service {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {
/// Requests read ahead of the one being handled; beyond this the session stops reading.
constexpr std::size_t kMaxPendingRequests = 8;
/// After an error reply, how long the client's remaining bytes are drained before closing.
constexpr double kLingerS = 2.0;
/// A client that sent a frame at least this large gives the heap's free pages back when it goes
/// (malloc_trim): its complete frames were copied into heap strings for the handler. Below it,
/// what it leaves is not worth the trim's cost. (Unfinished frames live in mappings of their own,
/// FrameBuffer, which go back to the system when they are dropped.)
constexpr std::size_t kLargeFrameBytes = 1u << 20;
/// Sessions hold their read buffer (64 KiB) in the heap, which keep_frame_buffers_in_heap() does
/// not trim: 300 idle connections opened and closed at once left 25-32 MiB behind
/// (DaemonLoadTest.RoundsOf*). Once this many bytes of sessions have gone since the last time,
/// the heap's free pages are given back.
constexpr std::size_t kGoneSessionBytesToGiveBack = std::size_t{8} << 20;
std::atomic<std::size_t> gone_session_bytes{0};
/// quiet_since_ns_ while the connection is in use, and once it was claimed for eviction.
constexpr std::int64_t kBusy = -1;
constexpr std::int64_t kClaimed = -2;

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string seconds(double s) {
  std::ostringstream os;
  os << s << " s";
  return os.str();
}
}  // namespace

Session::Session(tcp::socket socket, const SessionOptions& options, RequestHandler& handler,
                 ConnectionRegistry& registry, const LogSink& log, std::uint64_t number)
    : executor_(socket.get_executor()),
      socket_(std::move(socket)),
      timer_(executor_),
      options_(options),
      handler_(handler),
      registry_(registry),
      log_(log),
      number_(number),
      parser_(options.max_message_bytes, options.frame_budget),
      quiet_since_ns_(steady_now_ns()) {
  boost::system::error_code ec;
  const tcp::endpoint peer = socket_.remote_endpoint(ec);
  peer_ = ec ? std::string("unknown peer") : format_endpoint(peer);
}

Session::~Session() {
  handler_.unsubscribe(context_);
  std::size_t gone = gone_session_bytes.fetch_add(sizeof(Session)) + sizeof(Session);
  // One of the sessions going together resets the count and gives back (the others' bytes are
  // then counted towards the next time).
  if (gone >= kGoneSessionBytesToGiveBack && gone_session_bytes.compare_exchange_strong(gone, 0)) give_back_free_memory();
}

void Session::log(LogLevel level, const std::string& message) const {
  if (log_) log_(level, "client #" + std::to_string(number_) + " " + peer_ + ": " + message);
}

void Session::start() {
  context_.event_sink = [weak = weak_from_this(), executor = executor_](std::string payload) {
    if (auto self = weak.lock()) {
      asio::post(executor, [self, payload = std::move(payload)]() mutable { self->push_event(std::move(payload)); });
    }
  };
  log(LogLevel::kInfo, "connected");
  maybe_resume_reading();
}

void Session::start_rejected(ErrorCode code, const std::string& message) {
  log(LogLevel::kWarning, "rejected: " + message);
  fail_and_close(code, message);
}

void Session::stop() {
  asio::post(executor_, [self = shared_from_this()] { self->close("server stopping"); });
}

void Session::do_read() {
  if (reading_ || closed_) return;
  reading_ = true;
  socket_.async_read_some(asio::buffer(read_buffer_),
                          [self = shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
                            self->on_read(ec, n);
                          });
}

void Session::on_read(const boost::system::error_code& ec, std::size_t n) {
  reading_ = false;
  if (closed_) return;
  if (lingering_) {
    // Our side is shut down; drain what the client still sends until it closes too.
    if (ec) {
      close(close_reason_);
    } else {
      do_read();
    }
    return;
  }
  if (ec) {
    if (ec == asio::error::operation_aborted) return;
    if (ec == asio::error::eof && !parser_.has_partial() && !idle()) {
      // The client half-closed after its last request (as `nc -N` does): answer what it sent,
      // then close.
      peer_done_ = true;
      cancel_timer();
    } else if (ec == asio::error::eof || ec == asio::error::connection_reset) {
      close(parser_.has_partial() ? "client disconnected mid-frame (" + std::to_string(parser_.buffered_bytes()) +
                                        " bytes of an unfinished frame dropped)"
                                  : "client disconnected");
    } else {
      close("read failed: " + ec.message());
    }
    return;
  }
  if (closing_) {
    do_read();  // an error reply is being flushed; the client's bytes are ignored
    return;
  }
  // Claimed to make room for a newcomer before these bytes came: the eviction, already on its
  // way to this strand, answers them.
  if (!leave_quiet()) return;
  cancel_timer();  // progress: the stall clock restarts
  const bool was_partial = parser_.has_partial();
  const Status fed = parser_.feed(std::string_view(read_buffer_.data(), n));
  bool completed = false;
  while (auto frame = parser_.next()) {
    held_large_frame_ = held_large_frame_ || frame->size() >= kLargeFrameBytes;
    pending_bytes_ += frame->size();
    pending_.push_back(std::move(*frame));
    completed = true;
  }
  if (!fed && fed.error().code == ErrorCode::kUnavailable) {
    fail_and_close(ErrorCode::kUnavailable, "server busy: " + fed.error().message +
                                                " (server.max_buffered_bytes); send again later");
    return;
  }
  // The whole-frame clock: from the first byte of a frame until it is complete.
  if (!parser_.has_partial()) {
    frame_started_.reset();
  } else if (!was_partial || completed || !frame_started_) {
    frame_started_ = std::chrono::steady_clock::now();
  }
  if (!fed) {
    fail_and_close(ErrorCode::kInvalidArgument, "broken framing: " + fed.error().message);
    return;
  }
  dispatch_next();
  maybe_resume_reading();
}

bool Session::idle() const { return in_flight_ == 0 && pending_.empty() && outgoing_.empty(); }

void Session::maybe_resume_reading() {
  resume_reading();
  update_quiet();
}

// The quiet state is shared with the acceptor's thread, which may claim a quiet connection for
// eviction at any time: every change is a compare-and-swap, and a claim is never undone.
void Session::update_quiet() {
  const bool quiet = idle() && !parser_.has_partial() && context_.subscription < 0 && !closing_ && !closed_ && !lingering_;
  std::int64_t seen = quiet_since_ns_.load();
  if (seen == kClaimed) return;
  if (!quiet) {
    quiet_since_ns_.compare_exchange_strong(seen, kBusy);
  } else if (seen == kBusy) {
    quiet_since_ns_.compare_exchange_strong(seen, steady_now_ns());
  }
}

bool Session::leave_quiet() {
  std::int64_t seen = quiet_since_ns_.load();
  while (seen != kClaimed) {
    if (quiet_since_ns_.compare_exchange_weak(seen, kBusy)) return true;
  }
  return false;
}

bool Session::claim_for_eviction() {
  std::int64_t seen = quiet_since_ns_.load();
  while (seen >= 0) {
    if (quiet_since_ns_.compare_exchange_weak(seen, kClaimed)) return true;
  }
  return false;
}

void Session::evict(std::string reason) {
  asio::post(executor_, [self = shared_from_this(), reason = std::move(reason)] {
    self->fail_and_close(ErrorCode::kUnavailable, reason);
  });
}

void Session::resume_reading() {
  if (closing_ || closed_ || lingering_) return;
  if (peer_done_) {
    if (idle()) close("client disconnected");
    return;
  }
  if (!reading_) {
    // Back-pressure: a client that pipelines requests faster than they are answered, or does not
    // read its replies, is simply not read from until it catches up. Requests waiting hold at
    // most about one maximum-size message.
    if (pending_.size() >= kMaxPendingRequests || pending_bytes_ >= options_.max_message_bytes ||
        queued_bytes_ >= options_.max_queued_bytes) {
      cancel_timer();
      return;
    }
    do_read();
    if (parser_.has_partial()) {
      // The stall clock, but never past the frame's own deadline: a client that drips a byte
      // now and then keeps no frame open for ever.
      double wait = options_.read_timeout_s;
      if (frame_started_) {
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - *frame_started_).count();
        wait = std::max(0.0, std::min(wait, options_.frame_timeout_s - elapsed));
      }
      arm_timer(wait, &Session::on_stall_timeout);
    } else {
      cancel_timer();
    }
  }
}

// One request at a time, so that each sees what the ones before it did; the one exception is a
// frame that follows a frame: it is started (parsed and decoded on this strand) while the one
// before it is still processing, and the model's strand runs the two in order. Replies go out in
// the order the requests came. Not a live frame: that one waits, as a newer one may supersede it.
void Session::dispatch_next() {
  while (!pending_.empty() && !closing_ && !closed_) {
    skip_superseded_live_frames();
    const bool frame = handler_.is_ingest_frame(pending_.front()) && !handler_.is_live_frame(pending_.front());
    if (in_flight_ > 0 && !(in_flight_ == 1 && frame_in_flight_ && frame)) return;
    ++in_flight_;
    frame_in_flight_ = frame;
    std::string payload = std::move(pending_.front());
    pending_.pop_front();
    pending_bytes_ -= payload.size();
    auto self = shared_from_this();
    const std::uint64_t sequence = next_started_++;
    handler_.handle(std::move(payload), context_, [self, sequence](Reply reply) {
      // Possibly on a worker thread: continue on the strand.
      asio::post(self->executor_, [self, sequence, reply = std::move(reply)]() mutable {
        self->on_reply(sequence, std::move(reply));
      });
    });
  }
}

// A live stream that outpaces the model: a live frame with a newer live frame waiting behind it
// is answered "skipped" without being processed, so the model works on the newest frame and the
// queue never holds more than the frames that arrived during one frame's processing.
void Session::skip_superseded_live_frames() {
  auto newer_live_waiting = [&] {
    return std::any_of(pending_.begin() + 1, pending_.end(), [&](const std::string& p) { return handler_.is_live_frame(p); });
  };
  while (pending_.size() >= 2 && handler_.is_live_frame(pending_.front()) && newer_live_waiting()) {
    Reply reply = handler_.skip_live_frame(pending_.front());
    pending_bytes_ -= pending_.front().size();
    pending_.pop_front();
    answer(next_started_++, std::move(reply));  // after the reply of a frame still in flight
  }
}

void Session::on_reply(std::uint64_t sequence, Reply reply) {
  --in_flight_;
  if (closed_ || closing_) return;
  answer(sequence, std::move(reply));
  dispatch_next();
  maybe_resume_reading();
}

void Session::answer(std::uint64_t sequence, Reply reply) {
  early_replies_.emplace(sequence, std::move(reply));
  for (auto next = early_replies_.find(next_answered_); next != early_replies_.end();
       next = early_replies_.find(next_answered_)) {
    send_reply(std::move(next->second));
    early_replies_.erase(next);
    ++next_answered_;
  }
}

void Session::send_reply(Reply reply) {
  if (reply.ok) {
    log(LogLevel::kDebug, reply.call + " ok");
  } else {
    log(LogLevel::kWarning, reply.call + " failed: " + reply.error);
  }
  enqueue(std::move(reply.payload));
}

void Session::push_event(std::string payload) {
  if (closed_ || closing_) return;
  if (queued_bytes_ + kFrameHeaderBytes + payload.size() > options_.max_queued_bytes) {
    const std::string why = "subscriber too slow: " + std::to_string(queued_bytes_) +
                            " bytes already queued, limit " + std::to_string(options_.max_queued_bytes) +
                            " (server.max_queued_bytes)";
    log(LogLevel::kWarning, why + "; disconnecting");
    close(why);
    return;
  }
  enqueue(std::move(payload));
}

void Session::enqueue(std::string payload) {
  Outgoing out;
  const auto n = static_cast<std::uint32_t>(payload.size());
  out.header = {static_cast<unsigned char>(n >> 24), static_cast<unsigned char>(n >> 16),
                static_cast<unsigned char>(n >> 8), static_cast<unsigned char>(n)};
  out.payload = std::move(payload);
  queued_bytes_ += kFrameHeaderBytes + out.payload.size();
  outgoing_.push_back(std::move(out));
  if (!writing_) do_write();
}

void Session::do_write() {
  writing_ = true;
  const Outgoing& front = outgoing_.front();  // deque: stays put while others are appended
  const std::array<asio::const_buffer, 2> buffers{asio::buffer(front.header), asio::buffer(front.payload)};
  asio::async_write(socket_, buffers,
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      self->on_write(ec);
                    });
}

void Session::on_write(const boost::system::error_code& ec) {
  writing_ = false;
  if (closed_) return;
  if (ec) {
    close("write failed: " + ec.message());
    return;
  }
  queued_bytes_ -= kFrameHeaderBytes + outgoing_.front().payload.size();
  outgoing_.pop_front();
  if (!outgoing_.empty()) {
    do_write();
  } else if (closing_ && !lingering_) {
    begin_linger();
    return;
  }
  maybe_resume_reading();
}

void Session::arm_timer(double seconds, void (Session::*on_expiry)()) {
  const std::uint64_t generation = ++timer_generation_;
  timer_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(seconds)));
  timer_.async_wait([self = shared_from_this(), generation, on_expiry](const boost::system::error_code& ec) {
    if (ec || generation != self->timer_generation_ || self->closed_) return;
    ((*self).*on_expiry)();
  });
}

void Session::cancel_timer() {
  ++timer_generation_;
  timer_.cancel();
}

void Session::on_stall_timeout() {
  if (frame_started_ &&
      std::chrono::duration<double>(std::chrono::steady_clock::now() - *frame_started_).count() >= options_.frame_timeout_s) {
    fail_and_close(ErrorCode::kUnavailable, "frame timeout: " + std::to_string(parser_.buffered_bytes()) +
                                                " bytes of a frame in " + seconds(options_.frame_timeout_s) +
                                                ", not the whole of it (server.frame_timeout_s)");
    return;
  }
  fail_and_close(ErrorCode::kUnavailable,
                 "read timeout: " + std::to_string(parser_.buffered_bytes()) + " bytes of a frame arrived, then nothing for " +
                     seconds(options_.read_timeout_s) + " (server.read_timeout_s)");
}

void Session::on_linger_timeout() { close(close_reason_); }

void Session::fail_and_close(ErrorCode code, const std::string& message) {
  if (closing_ || closed_) return;
  log(LogLevel::kWarning, message + "; closing");
  closing_ = true;
  close_reason_ = message;
  pending_.clear();
  pending_bytes_ = 0;
  // No more of its bytes are read: the unfinished frame is dropped, and its share of the budget
  // given back, now rather than when the client finally goes.
  release_frame_memory();
  enqueue(handler_.error_payload(code, message));
  // The client may not read the error either: give the write as long as a stalled read.
  arm_timer(options_.read_timeout_s, &Session::on_linger_timeout);
}

void Session::begin_linger() {
  // Half-close and drain: closing with unread client bytes would send a reset that can destroy
  // the error reply before the client reads it.
  lingering_ = true;
  boost::system::error_code ignored;
  socket_.shutdown(tcp::socket::shutdown_send, ignored);
  arm_timer(kLingerS, &Session::on_linger_timeout);
  do_read();
}

void Session::release_frame_memory() {
  parser_.drop_partial();
  // glibc keeps freed frame-sized heap buffers (keep_frame_buffers_in_heap): once a client that
  // sent large frames goes, hand the heap's free pages back.
  if (std::exchange(held_large_frame_, false)) give_back_free_memory();
}

void Session::close(const std::string& reason) {
  if (closed_) return;
  closed_ = true;
  cancel_timer();
  handler_.unsubscribe(context_);
  boost::system::error_code ignored;
  socket_.shutdown(tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  pending_.clear();
  release_frame_memory();
  log(LogLevel::kInfo, "disconnected (" + reason + ")");
  registry_.remove(shared_from_this());
}

}  // namespace scenewatch::service
