#pragma once
/// The daemon side of the bridge: one thread sends the queued frames (IngestFrame) and, after each
/// reply, asks for the objects (GetObjects), the hands for the markers (GetHands), the surprise map
/// and, at most every map_period_s and once the stream pauses, the map (GetMap), with the next
/// frame's request pipelined behind these; a second thread writes what they answer to DDS, so the
/// next frame never waits for a write; a third holds a Subscribe connection and passes each
/// pushed event on.
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

  /// Starts the threads.
  void start();
  /// Queues a frame; when the queue is full the oldest one is dropped, counted and logged.
  void push(FrameJob job);
  /// Stops the threads (within about a second) and closes the connections; outputs already
  /// answered are published first.
  void stop();

 private:
  /// A connected client with the token set, retrying with backoff until connected or stopping.
  std::optional<service::Client> connect(const char* purpose);
  void ingest_loop();
  void subscribe_loop();
  /// A frame whose request is on the wire.
  struct InFlight {
    std::uint64_t id = 0;
    double stamp_s = 0.0;
    std::string camera_frame;  ///< where its heatmap is drawn
    Clock::time_point sent;
  };
  /// Converts a frame and puts its request on the wire. Nothing when the frame was dropped (bad
  /// input: counted and logged) or the connection broke (`broke` set; it is closed).
  std::optional<InFlight> start_frame(service::Client& client, const FrameJob& job, bool& broke);
  /// What one frame gives the DDS side, handed from the ingest thread to the publishing one.
  struct FrameOutputs {
    double stamp_s = 0.0;
    std::string camera_frame;
    Clock::time_point replied;  ///< when the frame's reply came (unset: a map alone)
    proto::IngestReply ingest;
    std::optional<proto::Response> objects, hands, surprise, map;
  };
  /// Waits for a frame's reply and the answers that follow from it, and hands them to the
  /// publishing thread. The frame's queries (objects, hands, surprise map, the map when due) go
  /// out together, and the next waiting frame's request follows them into `next` before their
  /// answers are awaited: the daemon answers one request at a time in order, so the queries see
  /// this frame's memory, and the next frame waits neither for a round trip nor for DDS writes.
  /// False: the connection broke (it is closed).
  bool finish_frame(service::Client& client, const InFlight& frame, std::optional<InFlight>& next);
  /// GetMap now (the stream paused), for the publishing thread.
  void request_map(service::Client& client, double stamp_s);
  /// The publishing thread: writes each frame's outputs in the order the frames came.
  void publish_loop();
  void publish(const FrameOutputs& frame);
  void publish_map(const proto::Response& answer, double stamp_s);
  void publish_markers(const proto::Response& hands, const proto::IngestReply& ingest, const proto::ObjectsReply& objects, double stamp_s);
  /// Publishes a frame's GetSurpriseMap answer, when the daemon had one for this very frame (none
  /// before the memory has keyframes).
  void publish_surprise(const proto::Response& answer, double stamp_s, const std::string& camera_frame);
  /// One call; a transport error (down, or slower than call_timeout_s) is logged and closes the
  /// connection, and gives nothing.
  std::optional<proto::Response> call(service::Client& client, proto::Request request, const char* what);
  /// call() in two halves, for pipelined requests: the request's id, or nothing (connection lost).
  std::optional<std::uint64_t> start(service::Client& client, proto::Request request, const char* what);
  std::optional<proto::Response> wait_for(service::Client& client, std::uint64_t id, const char* what);
  /// A transport error on `client`: logged, counted as connection_lost, the connection closed.
  /// Returns false (finish_frame's "the connection broke").
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
  // A few frames' outputs; should DDS writes fall behind further, the oldest go, counted.
  DropOldestQueue<FrameOutputs> outputs_{4};
  std::thread ingest_thread_, subscribe_thread_, publish_thread_;
  // The ingest thread's: when the map was last asked for, and whether a frame came since.
  double map_stamp_s_ = 0.0;  ///< stamp of the last frame whose map is not asked for yet
  bool map_dirty_ = false;
  Clock::time_point map_requested_{};
};

}  // namespace scenewatch::ros
