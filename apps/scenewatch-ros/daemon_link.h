#pragma once
/// The daemon side of the bridge: one thread sends the queued frames (IngestFrame) and, after each
/// reply, asks for the objects (GetObjects), the hands for the markers (GetHands) and, at most every
/// map_period_s and once the stream pauses, the map (GetMap); another holds a Subscribe connection and passes each pushed event on.
/// A daemon that is down, refuses, or answers slower than call_timeout_s is reconnected to with
/// backoff (0.1 s doubling up to max_backoff_s); the bridge keeps running meanwhile. Knows no DDS:
/// what arrives goes to the Outputs callbacks. Thread safe: push() from any thread.
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "bridge_config.h"
#include "bridge_stats.h"
#include "frame_assembler.h"
#include "frame_queue.h"
#include "recent_events.h"
#include "scene_markers.h"
#include "scenewatch.pb.h"
#include "scenewatch/service/client.h"

namespace scenewatch::ros {

/// Where the daemon's answers go (called on the link's threads).
struct Outputs {
  std::function<void(const std::vector<proto::Event>&)> events;
  std::function<void(const proto::ObjectsReply&, double stamp_s)> objects;
  std::function<void(const proto::MapReply&, double stamp_s)> map;
  std::function<void(const MarkerScene&, double stamp_s)> markers;  ///< unset: no markers
  std::function<void(const proto::Pose& T_world_odom, double stamp_s)> odom;  ///< unset: no /tf
  /// The frame's surprise heatmap, in the camera's frame; unset: no GetSurpriseMap calls.
  std::function<void(const proto::SurpriseMapReply&, double stamp_s, const std::string& camera_frame)> surprise;
  std::function<void(const std::string&)> log;
};

class DaemonLink {
 public:
  DaemonLink(const BridgeConfig& config, BridgeStats& stats, Outputs outputs);
  ~DaemonLink();
  DaemonLink(const DaemonLink&) = delete;
  DaemonLink& operator=(const DaemonLink&) = delete;

  /// Starts both threads.
  void start();
  /// Queues a frame; when the queue is full the oldest one is dropped, counted and logged.
  void push(FrameJob job);
  /// Stops both threads (within about a second) and closes the connections.
  void stop();

 private:
  /// A connected client with the token set, retrying with backoff until connected or stopping.
  std::optional<service::Client> connect(const char* purpose);
  void ingest_loop();
  void subscribe_loop();
  /// Converts and sends one frame, then publishes what follows from its reply. False: the
  /// connection broke (it is closed).
  bool send_frame(service::Client& client, const FrameJob& job);
  void publish_map(service::Client& client, double stamp_s);
  /// After a frame's objects: fetches the hands and publishes the markers. False: the connection
  /// broke.
  bool publish_markers(service::Client& client, const proto::IngestReply& ingest, const proto::ObjectsReply& objects, double stamp_s);
  /// After a frame: fetches its surprise map and publishes it, when the daemon has one for this very
  /// frame (none before the memory has keyframes). False: the connection broke.
  bool publish_surprise(service::Client& client, double stamp_s, const std::string& camera_frame);
  /// One call; a transport error (down, or slower than call_timeout_s) is logged and closes the
  /// connection, and gives nothing.
  std::optional<proto::Response> call(service::Client& client, proto::Request request, const char* what);
  /// A transport error on `client`: logged, counted as connection_lost, the connection closed.
  /// Returns false (send_frame's "the connection broke").
  bool lose(service::Client& client, const char* what, const std::string& why);
  /// Waits up to seconds unless stopping; false when stopping.
  bool sleep_for(double seconds);

  const BridgeConfig& config_;
  BridgeStats& stats_;
  Outputs out_;
  std::string token_;
  DropOldestQueue<FrameJob> queue_;
  RecentEvents recent_events_;
  std::atomic<bool> stopping_{false};
  std::thread ingest_thread_, subscribe_thread_;
  double map_stamp_s_ = 0.0;  ///< stamp of the last frame whose map is not published yet
  bool map_dirty_ = false;
  Clock::time_point map_published_{};
};

}  // namespace scenewatch::ros
