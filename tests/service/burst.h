#pragma once
// What a hostile client sends all at once, for the tests of the daemon's limits: many idle
// connections opened in a burst, many clients each sending half of a large frame and vanishing,
// and the daemon's resident memory sampled meanwhile.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/core/memory.h"

namespace scenewatch::test {

/// Samples a process's VmRSS every 20 ms on a thread of its own and keeps the peak.
class RssSampler {
 public:
  explicit RssSampler(pid_t pid) : pid_(pid), peak_mib_(resident_mib(pid)), thread_([this] { run(); }) {}
  ~RssSampler() { stop(); }
  RssSampler(const RssSampler&) = delete;
  RssSampler& operator=(const RssSampler&) = delete;

  /// Stops sampling; returns the peak seen (MiB).
  double stop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
    return peak_mib_;
  }

 private:
  void run() {
    while (!done_) {
      peak_mib_ = std::max(peak_mib_.load(), resident_mib(pid_));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  pid_t pid_;
  std::atomic<double> peak_mib_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

/// The daemon's count of connected clients (StatsReply.connections), asked on a new connection,
/// which counts itself.
inline std::uint32_t connections_now(const Daemon& daemon) {
  service::Client probe = daemon.connect_without_token();
  return call(probe, request([](proto::Request& r) { r.mutable_stats(); })).stats().connections();
}

/// Asks connections_now() every 100 ms, for at most 30 s, until it gives `wanted` (or less); the
/// last answer.
inline std::uint32_t wait_for_connections(const Daemon& daemon, std::uint32_t wanted) {
  std::uint32_t now = connections_now(daemon);
  for (int attempt = 0; attempt < 300 && now > wanted; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    now = connections_now(daemon);
  }
  return now;
}

/// Opens `n` connections to the daemon as fast as one thread can, sending nothing on them.
inline std::vector<service::Client> open_idle_connections(const Daemon& daemon, int n) {
  std::vector<service::Client> clients;
  clients.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) clients.push_back(daemon.connect_without_token());
  return clients;
}

/// How a burst of idle connections ended: told to make room or turned away (an UNAVAILABLE
/// reply, then closed), or still open.
struct IdleOutcome {
  int closed = 0;
  int still_open = 0;
};

/// Looks at each connection once (waiting at most `wait_s` for a reply on each).
inline IdleOutcome idle_outcome(std::vector<service::Client>& clients, double wait_s) {
  IdleOutcome outcome;
  for (auto& c : clients) {
    auto reply = c.receive(wait_s);
    if (reply.ok() && reply->status().code() == proto::Status::UNAVAILABLE) {
      ++outcome.closed;
    } else if (!reply.ok() && c.is_open() && reply.error().message.find("no answer from") != std::string::npos) {
      ++outcome.still_open;
    } else {
      ++outcome.closed;
    }
  }
  return outcome;
}

/// A frame header announcing `bytes` of payload.
inline std::string frame_header(std::uint32_t bytes) {
  return {static_cast<char>(bytes >> 24), static_cast<char>(bytes >> 16), static_cast<char>(bytes >> 8),
          static_cast<char>(bytes)};
}

/// What a burst of half frames did.
struct HalfFrames {
  int busy = 0;           ///< clients told "server busy" (server.max_buffered_bytes)
  int send_failed = 0;    ///< clients whose half could not be sent whole (closed on them first)
  double peak_mib = 0;    ///< the daemon's VmRSS at its peak while they held their halves
};

/// `clients` clients connect, each announces a frame of `frame_bytes` and sends half of it, all
/// at once; once every one has sent (or failed to), each reads whether it was told the server is
/// busy, and all vanish together.
inline HalfFrames send_half_frames_and_vanish(const Daemon& daemon, int clients, std::uint32_t frame_bytes) {
  const std::string half = frame_header(frame_bytes) + std::string(frame_bytes / 2, 'h');
  std::vector<service::Client> connections = open_idle_connections(daemon, clients);
  std::atomic<int> busy{0}, send_failed{0};
  std::mutex mutex;
  std::condition_variable all_sent;
  int sent = 0;
  RssSampler rss(daemon.pid());
  std::vector<std::thread> threads;
  for (auto& c : connections) {
    threads.emplace_back([&, client = &c] {
      if (!client->send_raw(half).ok()) ++send_failed;
      {
        std::unique_lock<std::mutex> lock(mutex);
        ++sent;
        all_sent.notify_all();
        all_sent.wait(lock, [&] { return sent == clients; });
      }
      auto reply = client->receive(1.0);
      if (reply.ok() && reply->status().code() == proto::Status::UNAVAILABLE &&
          reply->status().message().find("server.max_buffered_bytes") != std::string::npos) {
        ++busy;
      }
    });
  }
  for (auto& t : threads) t.join();
  HalfFrames result;
  result.peak_mib = rss.stop();
  result.busy = busy;
  result.send_failed = send_failed;
  for (auto& c : connections) c.close();
  return result;
}

}  // namespace scenewatch::test
