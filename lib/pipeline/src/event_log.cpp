// The working memory's event log and its subscribers (event_log.h).
#include "event_log.h"

#include <algorithm>

namespace scenewatch::pipeline {

void EventLog::emit(std::vector<Event>& batch, std::size_t max_log) {
  std::vector<Callback> callbacks;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& e : batch) {
      e.id = next_id_++;
      events_.push_back(e);
      ++emitted_;
    }
    while (events_.size() > max_log) events_.pop_front();
    for (const auto& [token, cb] : subscribers_) callbacks.push_back(cb);
  }
  for (const auto& e : batch)
    for (const auto& cb : callbacks) cb(e);
}

int EventLog::subscribe(Callback callback) {
  std::lock_guard<std::mutex> lock(mutex_);
  const int token = next_token_++;
  subscribers_.emplace(token, std::move(callback));
  return token;
}

void EventLog::unsubscribe(int token) {
  std::lock_guard<std::mutex> lock(mutex_);
  subscribers_.erase(token);
}

std::vector<Event> EventLog::since(std::uint64_t since, std::size_t max_count) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Event> out;
  for (const auto& e : events_) {
    if (e.id > since && out.size() < max_count) out.push_back(e);
  }
  return out;
}

std::optional<std::uint64_t> EventLog::confirmed_by(std::uint64_t pending_id) const {
  // A linear search: asked only of an id that is no longer pending, over a bounded log.
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto e = events_.rbegin(); e != events_.rend(); ++e) {
    if (std::find(e->pending_ids.begin(), e->pending_ids.end(), pending_id) != e->pending_ids.end()) return e->id;
  }
  return std::nullopt;
}

std::uint64_t EventLog::emitted() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return emitted_;
}

void EventLog::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  events_.clear();
}

std::pair<std::deque<Event>, std::uint64_t> EventLog::contents() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {events_, next_id_};
}

void EventLog::restore(std::deque<Event> events, std::uint64_t next_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  events_ = std::move(events);
  next_id_ = std::max(next_id, events_.empty() ? 1 : events_.back().id + 1);
}

}  // namespace scenewatch::pipeline
