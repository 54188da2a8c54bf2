#include "recent_events.h"

namespace scenewatch::ros {

void RecentEvents::add(const proto::Event& event) {
  if (capacity_ == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  by_id_.emplace(event.id(), event);
  while (by_id_.size() > capacity_) by_id_.erase(by_id_.begin());
}

std::vector<proto::Event> RecentEvents::newest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<proto::Event> out;
  out.reserve(by_id_.size());
  for (const auto& [id, event] : by_id_) out.push_back(event);
  return out;
}

}  // namespace scenewatch::ros
