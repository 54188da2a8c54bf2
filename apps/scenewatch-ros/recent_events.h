#pragma once
/// The newest events the bridge has seen, for the marker array: the daemon reports an event both
/// in the IngestReply of the frame that raised it and on the Subscribe connection, so both feed
/// this store and it keeps each event once (by id). Thread safe: add() from the ingest and the
/// subscribe threads, newest() from the publishing thread.
#include <cstddef>
#include <map>
#include <mutex>
#include <vector>

#include "scenewatch.pb.h"

namespace scenewatch::ros {

class RecentEvents {
 public:
  /// Keeps at most `capacity` events (0: none).
  explicit RecentEvents(std::size_t capacity) : capacity_(capacity) {}

  /// Adds an event unless one with its id is held; beyond the capacity the oldest id goes.
  void add(const proto::Event& event);
  /// The events held, oldest id first.
  std::vector<proto::Event> newest() const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::map<std::uint64_t, proto::Event> by_id_;  ///< ids increase with time: the first is the oldest
};

}  // namespace scenewatch::ros
