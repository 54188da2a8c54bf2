#include "connection_registry.h"

#include <vector>

#include "session.h"

namespace scenewatch::service {

Admission ConnectionRegistry::admit(const std::shared_ptr<Session>& session, std::size_t limit) {
  std::lock_guard<std::mutex> lock(mutex_);
  Admission admission;
  if (stopped_) return admission;
  if (counted_.size() >= limit) {
    admission.evicted = claim_quietest();
    if (!admission.evicted) {
      leaving_.insert(session);
      admission.kind = Admission::Kind::kRefused;
      return admission;
    }
    counted_.erase(admission.evicted);
    leaving_.insert(admission.evicted);
  }
  counted_.insert(session);
  admission.kind = Admission::Kind::kAdmitted;
  return admission;
}

std::shared_ptr<Session> ConnectionRegistry::claim_quietest() {
  // A candidate may become busy between the scan and the claim: then scan again without it.
  std::set<std::shared_ptr<Session>> passed_over;
  for (;;) {
    std::shared_ptr<Session> best;
    std::int64_t best_since = -1;
    for (const auto& s : counted_) {
      const std::int64_t since = s->quiet_since_ns();
      if (since < 0 || passed_over.count(s) > 0) continue;
      if (!best || since < best_since) {
        best = s;
        best_since = since;
      }
    }
    if (!best || best->claim_for_eviction()) return best;
    passed_over.insert(best);
  }
}

void ConnectionRegistry::remove(const std::shared_ptr<Session>& session) {
  std::lock_guard<std::mutex> lock(mutex_);
  counted_.erase(session);
  leaving_.erase(session);
}

void ConnectionRegistry::stop_all() {
  std::vector<std::shared_ptr<Session>> sessions;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    sessions.assign(counted_.begin(), counted_.end());
    sessions.insert(sessions.end(), leaving_.begin(), leaving_.end());
  }
  for (const auto& session : sessions) session->stop();
}

std::size_t ConnectionRegistry::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counted_.size();
}

}  // namespace scenewatch::service
