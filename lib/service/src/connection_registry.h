#pragma once
// The open connections: which of them count against server.max_connections, and all of them, so
// that the server can stop them. Admission is decided here, once per accepted connection, under
// one lock: a burst of newcomers can neither go beyond the limit nor pick the same connection to
// make room twice.
#include <cstddef>
#include <memory>
#include <mutex>
#include <set>

namespace scenewatch::service {

class Session;

/// What admit() decided for a newcomer.
struct Admission {
  enum class Kind {
    kAdmitted,  ///< counted; `evicted`, when set, was claimed to make room and must be evicted
    kRefused,   ///< at the limit and no connection can be closed: answer UNAVAILABLE and close
    kStopping,  ///< stop_all() ran: just let it close
  };
  Kind kind = Kind::kStopping;
  std::shared_ptr<Session> evicted;
};

/// Thread safe: the acceptor admits, sessions remove themselves from their own strands.
class ConnectionRegistry {
 public:
  /// Counts `session` when fewer than `limit` are counted. At the limit it takes the place of the
  /// connection quiet for longest that can still be closed (Session::claim_for_eviction(), so a
  /// connection that became busy meanwhile, or is already being evicted, is passed over); else it
  /// is refused. Evicted and refused connections stay known to stop_all() until they close, but
  /// no longer count.
  Admission admit(const std::shared_ptr<Session>& session, std::size_t limit);
  /// Forgets a session (closed); thread safe.
  void remove(const std::shared_ptr<Session>& session);
  /// Asks every session to close; later admit() calls answer kStopping.
  void stop_all();
  /// The connections counted against the limit.
  std::size_t size() const;

 private:
  /// The quiet counted session with the oldest quiet_since_ns, claimed for eviction; null when
  /// none can be claimed. Called with mutex_ held.
  std::shared_ptr<Session> claim_quietest();

  mutable std::mutex mutex_;
  std::set<std::shared_ptr<Session>> counted_;
  std::set<std::shared_ptr<Session>> leaving_;  ///< evicted or refused, not yet closed
  bool stopped_ = false;
};

}  // namespace scenewatch::service
