#pragma once
// The set of open connections, so that the server can stop them all.
#include <cstddef>
#include <memory>
#include <mutex>
#include <set>

namespace scenewatch::service {

class Session;

/// Thread safe: sessions add and remove themselves from their own strands.
class ConnectionRegistry {
 public:
  /// Adds a session; returns the number of connections including it, or 0 (and does not add it)
  /// once stop_all() has run.
  std::size_t add(const std::shared_ptr<Session>& session);
  void remove(const std::shared_ptr<Session>& session);
  /// Asks every session to close; later add() calls are refused.
  void stop_all();
  std::size_t size() const;
  /// The session quiet for longest (Session::quiet_since_ns), other than `except`; null when none
  /// is quiet.
  std::shared_ptr<Session> quietest(const std::shared_ptr<Session>& except) const;

 private:
  mutable std::mutex mutex_;
  std::set<std::shared_ptr<Session>> sessions_;
  bool stopped_ = false;
};

}  // namespace scenewatch::service
