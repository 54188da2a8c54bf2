#pragma once
// The events a working memory emitted: ids handed out in order, the newest `max_log` kept for
// GetEvents, and the subscribers each new event is delivered to. Thread safe: emit() runs on the
// writer's thread, the readers and subscribe() on any.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "scenewatch/core/event.h"

namespace scenewatch::pipeline {

class EventLog {
 public:
  using Callback = std::function<void(const Event&)>;

  /// Gives each event of `batch` its id, keeps it (the oldest beyond `max_log` go), then delivers
  /// the batch to every subscriber outside the lock.
  void emit(std::vector<Event>& batch, std::size_t max_log);
  int subscribe(Callback callback);
  void unsubscribe(int token);
  /// Events with id > since, oldest first, at most max_count.
  std::vector<Event> since(std::uint64_t since, std::size_t max_count) const;
  /// The id of the kept event that confirmed pending change `pending_id` (Event::pending_ids);
  /// nullopt when no kept event names it.
  std::optional<std::uint64_t> confirmed_by(std::uint64_t pending_id) const;
  /// Events emitted since the start (not lessened by clear()).
  std::uint64_t emitted() const;
  /// Forgets the kept events; ids keep counting, so none is given twice.
  void clear();
  /// The kept events and the next id, consistent with each other (for saving).
  std::pair<std::deque<Event>, std::uint64_t> contents() const;
  /// A loaded log in place of this one; ids go on from `next_id` or past its newest event.
  void restore(std::deque<Event> events, std::uint64_t next_id);

 private:
  mutable std::mutex mutex_;
  std::deque<Event> events_;
  std::uint64_t next_id_ = 1;
  std::uint64_t emitted_ = 0;
  std::map<int, Callback> subscribers_;
  int next_token_ = 1;
};

}  // namespace scenewatch::pipeline
