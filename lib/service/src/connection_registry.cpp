#include "connection_registry.h"

#include <vector>

#include "session.h"

namespace scenewatch::service {

std::size_t ConnectionRegistry::add(const std::shared_ptr<Session>& session) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return 0;
  sessions_.insert(session);
  return sessions_.size();
}

void ConnectionRegistry::remove(const std::shared_ptr<Session>& session) {
  std::lock_guard<std::mutex> lock(mutex_);
  sessions_.erase(session);
}

void ConnectionRegistry::stop_all() {
  std::vector<std::shared_ptr<Session>> sessions;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    sessions.assign(sessions_.begin(), sessions_.end());
  }
  for (const auto& session : sessions) session->stop();
}

std::shared_ptr<Session> ConnectionRegistry::quietest(const std::shared_ptr<Session>& except) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::shared_ptr<Session> best;
  std::int64_t best_since = -1;
  for (const auto& s : sessions_) {
    const std::int64_t since = s->quiet_since_ns();
    if (s == except || since < 0) continue;
    if (!best || since < best_since) {
      best = s;
      best_since = since;
    }
  }
  return best;
}

std::size_t ConnectionRegistry::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sessions_.size();
}

}  // namespace scenewatch::service
