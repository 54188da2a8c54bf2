#pragma once
/// A bounded queue between the DDS side and the daemon: when it is full, push() drops the oldest
/// item and hands it back, so that large images never pile up behind a slow daemon and the newest
/// frame is always the next one sent. Thread safe.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace scenewatch::ros {

template <typename T>
class DropOldestQueue {
 public:
  explicit DropOldestQueue(std::size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  /// Adds an item; returns the one dropped to make room (nothing when there was room).
  std::optional<T> push(T item) {
    std::optional<T> dropped;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (items_.size() >= capacity_) {
        dropped = std::move(items_.front());
        items_.pop_front();
      }
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
    return dropped;
  }

  /// The oldest item, waiting at most timeout_s; nothing on timeout or after close().
  std::optional<T> pop(double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    return item;
  }

  /// Wakes every pop(); later pops return what is left, then nothing.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

 private:
  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace scenewatch::ros
