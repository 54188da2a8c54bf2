#include "daemon_link.h"

#include <cmath>

#include <algorithm>

#include "scenewatch/io/bag/image_conversion.h"
#include "scenewatch/service/access_token.h"

namespace scenewatch::ros {
namespace {

double ms_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

/// A frame's IngestFrame: its depth and colour images as they are (the daemon back-projects them),
/// or the points of its PointCloud2. The error names the topic at fault; `reason` is the drop
/// counter's name.
Result<proto::IngestFrame> request_of(const FrameJob& job, const BridgeConfig& config, std::string& reason) {
  Frame frame;
  frame.T_world_camera = job.T_world_camera;
  frame.stamp_s = job.stamp_s();
  frame.camera = config.camera_name;
  if (!job.T_world_camera) frame.localization = LocalizationMode::kTrack;  // --without-tf track
  if (job.cloud) {
    reason = "bad_cloud";
    auto points = io::bag::to_cloud_frame(cloud_view(*job.cloud), job.intrinsics);
    if (!points) return Error{points.error().code, config.cloud_topic + ": " + points.error().message};
    frame.cloud = points->cloud;
    frame.has_color = points->has_color;
    frame.intrinsics = points->intrinsics;
    frame.source = config.cloud_topic;
    return service::make_ingest_frame(frame);
  }
  reason = "bad_image";
  const auto depth = image_view(job.depth);
  std::optional<io::bag::ImageMessage> color;
  if (job.color) color = image_view(*job.color);
  bool color_at_fault = false;
  auto images = io::bag::to_rgbd_images(depth, color ? &*color : nullptr, *job.intrinsics, config.info_topic, &color_at_fault);
  if (!images) return Error{images.error().code, (color_at_fault ? config.color_topic : config.depth_topic) + ": " + images.error().message};
  frame.intrinsics = images->intrinsics;
  frame.source = config.depth_topic;
  proto::IngestFrame msg = service::make_ingest_frame(frame);
  service::set_rgbd_images(images->depth, images->has_color ? &images->color : nullptr, &msg);
  return msg;
}

}  // namespace

DaemonLink::DaemonLink(const BridgeConfig& config, BridgeStats& stats, Outputs outputs)
    : config_(config), stats_(stats), out_(std::move(outputs)), queue_(config.queue_frames), recent_events_(config.marker_events) {}

DaemonLink::~DaemonLink() { stop(); }

void DaemonLink::start() {
  ingest_thread_ = std::thread([this] { ingest_loop(); });
  subscribe_thread_ = std::thread([this] { subscribe_loop(); });
  publish_thread_ = std::thread([this] { publish_loop(); });
}

void DaemonLink::stop() {
  stopping_ = true;
  queue_.close();
  if (ingest_thread_.joinable()) ingest_thread_.join();
  if (subscribe_thread_.joinable()) subscribe_thread_.join();
  outputs_.close();
  if (publish_thread_.joinable()) publish_thread_.join();
}

void DaemonLink::push(FrameJob job) {
  auto dropped = queue_.push(std::move(job));
  if (!dropped) return;
  const auto n = stats_.count("dropped.queue_full");
  if (worth_logging(n)) {
    out_.log("dropped the frame of " + seconds(dropped->stamp_s()) + " s (queue_full, " + std::to_string(n) +
             " so far): the daemon is slower than the camera; " + std::to_string(config_.queue_frames) +
             " newer frames wait (--queue-frames)");
  }
}

bool DaemonLink::sleep_for(double s) {
  const auto until = Clock::now() + std::chrono::duration<double>(s);
  while (!stopping_ && Clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return !stopping_;
}

std::optional<service::Client> DaemonLink::connect(const char* purpose) {
  double backoff_s = 0.1;
  for (std::uint64_t attempt = 1; !stopping_; ++attempt) {
    auto client = service::Client::connect(config_.host, config_.port, std::min(2.0, config_.call_timeout_s));
    if (client) {
      if (token_.empty()) {
        const auto path = config_.token_file.empty() ? service::default_token_path() : std::filesystem::path(config_.token_file);
        auto token = service::read_token_file(path);
        if (token) {
          token_ = *token;
        } else {
          out_.log("no access token (" + token.error().message + "): the daemon will refuse the frames");
        }
      }
      client->set_token(token_);
      out_.log(std::string("connected to ") + client->endpoint() + " (" + purpose + ")");
      return std::move(*client);
    }
    const auto n = stats_.count(std::string("reconnects.") + purpose);
    if (worth_logging(n)) {
      out_.log(std::string(purpose) + ": " + client.error().message + "; retrying in " + seconds(backoff_s) + " s (attempt " +
               std::to_string(attempt) + ")");
    }
    if (!sleep_for(backoff_s)) break;
    backoff_s = std::min(backoff_s * 2, config_.max_backoff_s);
  }
  return std::nullopt;
}

void DaemonLink::ingest_loop() {
  while (!stopping_) {
    auto client = connect("ingest");
    if (!client) return;
    std::optional<InFlight> in_flight;
    while (!stopping_ && client->is_open()) {
      if (!in_flight) {
        auto job = queue_.pop(0.2);
        if (!job) {
          // The stream paused: the map of its last frame goes out now.
          if (map_dirty_) request_map(*client, map_stamp_s_);
          continue;
        }
        bool broke = false;
        in_flight = start_frame(*client, *job, broke);
        if (broke) break;
        if (!in_flight) continue;
      }
      std::optional<InFlight> next;
      const bool ok = finish_frame(*client, *in_flight, next);
      in_flight = std::move(next);
      if (!ok) break;
    }
    // A frame whose request went out on the connection that broke is lost with it.
    if (in_flight) stats_.count("dropped.connection_lost");
    client->close();
  }
}

std::optional<DaemonLink::InFlight> DaemonLink::start_frame(service::Client& client, const FrameJob& job, bool& broke) {
  const auto dequeued = Clock::now();
  std::string reason;
  auto message = request_of(job, config_, reason);
  if (!message) {
    const auto n = stats_.count("dropped." + reason);
    if (worth_logging(n)) {
      out_.log("dropped the frame of " + seconds(job.stamp_s()) + " s (" + reason + ", " + std::to_string(n) + " so far): " +
               message.error().message);
    }
    return std::nullopt;
  }
  proto::Request request;
  auto* ingest = request.mutable_ingest_frame();
  *ingest = std::move(*message);
  ingest->set_live(true);
  const auto encoded = Clock::now();
  auto id = client.start(std::move(request));
  const auto sent = Clock::now();
  if (!id) {
    stats_.count("dropped.connection_lost");
    lose(client, "ingest", id.error().message);
    broke = true;
    return std::nullopt;
  }
  stats_.sample_ms("in.arrival_to_request", ms_between(job.arrived, sent));
  stats_.sample_ms("in.1_queued", ms_between(job.arrived, dequeued));
  stats_.sample_ms("in.2_converted", ms_between(dequeued, encoded));
  stats_.sample_ms("in.3_written", ms_between(encoded, sent));
  return InFlight{*id, job.stamp_s(), config_.camera_frame.empty() ? job.frame_id() : config_.camera_frame, sent};
}

bool DaemonLink::finish_frame(service::Client& client, const InFlight& frame, std::optional<InFlight>& next) {
  // The next waiting frame goes on the wire as soon as the requests it must follow are out.
  auto take_next = [&] {
    if (next) return true;
    auto job = queue_.pop(0.0);
    if (!job) return true;
    bool broke = false;
    next = start_frame(client, *job, broke);
    return !broke;
  };
  auto reply = client.wait_for(frame.id, config_.call_timeout_s);
  if (!reply) {
    stats_.count("dropped.connection_lost");
    return lose(client, "ingest", reply.error().message);
  }
  FrameOutputs out;
  out.replied = Clock::now();
  out.stamp_s = frame.stamp_s;
  out.camera_frame = frame.camera_frame;
  stats_.sample_ms("daemon.request_to_reply", ms_between(frame.sent, out.replied));
  if (auto st = service::status_of(*reply); !st) {
    const auto n = stats_.count("refused");
    if (worth_logging(n)) out_.log("the daemon refused the frame of " + seconds(frame.stamp_s) + " s: " + st.error().message);
    return true;
  }
  if (reply->ingest().skipped()) {
    stats_.count("skipped_by_daemon");
    return true;
  }
  stats_.count("frames_sent");
  out.ingest = std::move(*reply->mutable_ingest());
  for (const auto& event : out.ingest.events()) recent_events_.add(event);

  struct Query {
    std::optional<proto::Response>* answer;
    const char* what;
    std::uint64_t id;
  };
  std::vector<Query> queries;
  auto ask = [&](std::optional<proto::Response>& answer, const char* what, auto set) {
    proto::Request request;
    set(request);
    auto id = start(client, std::move(request), what);
    if (id) queries.push_back({&answer, what, *id});
    return id.has_value();
  };
  if (!ask(out.objects, "objects", [](proto::Request& r) { r.mutable_get_objects(); })) return false;
  if (out_.markers && !ask(out.hands, "hands", [](proto::Request& r) { r.mutable_get_hands(); })) return false;
  if (out_.surprise && !ask(out.surprise, "surprise", [](proto::Request& r) { r.mutable_get_surprise_map(); })) return false;
  map_stamp_s_ = frame.stamp_s;
  map_dirty_ = true;
  if (Clock::now() - map_requested_ >= std::chrono::duration<double>(config_.map_period_s)) {
    if (!ask(out.map, "map", [](proto::Request& r) { r.mutable_get_map(); })) return false;
    map_requested_ = Clock::now();
    map_dirty_ = false;
  }
  for (const Query& q : queries) {
    if (!take_next()) return false;
    *q.answer = wait_for(client, q.id, q.what);
    if (!*q.answer) return false;
    // The objects, a small message, go out at once; the heavy writes are the other thread's.
    if (q.answer == &out.objects && service::status_of(*out.objects)) {
      out_.objects(out.objects->objects(), frame.stamp_s);
      stats_.sample_ms("out.reply_to_objects_written", ms_between(out.replied, Clock::now()));
    }
  }
  if (auto dropped = outputs_.push(std::move(out))) {
    // Not "dropped.": that counts frames the daemon never saw; this one it did.
    const auto n = stats_.count("outputs_dropped");
    if (worth_logging(n)) out_.log("the outputs of the frame of " + seconds(dropped->stamp_s) + " s were not published (" +
                                   std::to_string(n) + " so far): writing to DDS is slower than the daemon");
  }
  return take_next();
}

void DaemonLink::publish_loop() {
  // Until stop(): close() wakes the pop, and what was queued before it still goes out.
  for (;;) {
    auto frame = outputs_.pop(3600.0);
    if (frame) {
      publish(*frame);
    } else if (stopping_) {
      return;
    }
  }
}

void DaemonLink::publish(const FrameOutputs& frame) {
  // The frame's camera's T_world_odom, as the daemon holds it after this frame (identity in
  // `given` mode: the given poses are world poses).
  if (out_.odom && frame.ingest.has_localization()) {
    out_.odom(frame.ingest.localization().t_world_odom(), frame.stamp_s);
    stats_.count("odom_sent");
  }
  if (frame.hands && frame.objects && service::status_of(*frame.objects))
    publish_markers(*frame.hands, frame.ingest, frame.objects->objects(), frame.stamp_s);
  if (frame.surprise) publish_surprise(*frame.surprise, frame.stamp_s, frame.camera_frame);
  if (frame.map) publish_map(*frame.map, frame.stamp_s);
}

std::optional<proto::Response> DaemonLink::call(service::Client& client, proto::Request request, const char* what) {
  auto answer = client.call(std::move(request), config_.call_timeout_s);
  if (answer) return std::move(*answer);
  lose(client, what, answer.error().message);
  return std::nullopt;
}

std::optional<std::uint64_t> DaemonLink::start(service::Client& client, proto::Request request, const char* what) {
  auto id = client.start(std::move(request));
  if (id) return *id;
  lose(client, what, id.error().message);
  return std::nullopt;
}

std::optional<proto::Response> DaemonLink::wait_for(service::Client& client, std::uint64_t id, const char* what) {
  auto answer = client.wait_for(id, config_.call_timeout_s);
  if (answer) return std::move(*answer);
  lose(client, what, answer.error().message);
  return std::nullopt;
}

bool DaemonLink::lose(service::Client& client, const char* what, const std::string& why) {
  out_.log(std::string(what) + ": " + why + "; reconnecting");
  stats_.count("connection_lost");
  client.close();
  return false;
}

void DaemonLink::request_map(service::Client& client, double stamp_s) {
  proto::Request request;
  request.mutable_get_map();
  FrameOutputs out;
  out.stamp_s = stamp_s;
  out.map = call(client, std::move(request), "map");
  if (!out.map) return;
  map_requested_ = Clock::now();
  map_dirty_ = false;
  outputs_.push(std::move(out));
}

void DaemonLink::publish_map(const proto::Response& answer, double stamp_s) {
  if (auto st = service::status_of(answer); !st) {
    const auto n = stats_.count("map_refused");
    if (worth_logging(n)) out_.log("the daemon refused GetMap: " + st.error().message);
    return;
  }
  out_.map(answer.map(), stamp_s);
  stats_.count("maps_sent");
}

void DaemonLink::publish_markers(const proto::Response& hands, const proto::IngestReply& ingest, const proto::ObjectsReply& objects,
                                 double stamp_s) {
  MarkerScene scene;
  scene.planes = &ingest.planes();
  scene.objects = &objects;
  // An older daemon without GetHands still gets the other markers.
  if (service::status_of(hands)) scene.hands = &hands.hands();
  scene.events = recent_events_.newest();
  out_.markers(scene, stamp_s);
  stats_.count("markers_sent");
}

void DaemonLink::publish_surprise(const proto::Response& answer, double stamp_s, const std::string& camera_frame) {
  if (auto st = service::status_of(answer); !st) {
    // NOT_FOUND until the memory has keyframes: expected at the start, not worth a log line.
    if (st.error().code == ErrorCode::kNotFound) {
      stats_.count("surprise_none");
    } else if (const auto n = stats_.count("surprise_refused"); worth_logging(n)) {
      out_.log("the daemon refused GetSurpriseMap: " + st.error().message);
    }
    return;
  }
  // The daemon answers with the last frame that had a map: an older frame's is not this one's.
  if (std::abs(answer.surprise_map().stamp_s() - stamp_s) > 1e-6) {
    stats_.count("surprise_none");
    return;
  }
  out_.surprise(answer.surprise_map(), stamp_s, camera_frame);
  stats_.count("surprise_sent");
}

void DaemonLink::subscribe_loop() {
  while (!stopping_) {
    auto client = connect("events");
    if (!client) return;
    proto::Request subscribe;
    subscribe.mutable_subscribe();
    auto subscribed = client->call(std::move(subscribe), config_.call_timeout_s);
    if (!subscribed || !service::status_of(*subscribed)) {
      out_.log("events: Subscribe failed: " + (subscribed ? service::status_of(*subscribed).error().message : subscribed.error().message));
      if (!sleep_for(config_.max_backoff_s)) return;
      continue;
    }
    while (!stopping_) {
      auto pushed = client->next_pushed(0.5);
      if (!pushed) {
        if (client->is_open()) continue;  // nothing within the wait
        out_.log("events: " + pushed.error().message + "; reconnecting");
        stats_.count("connection_lost");
        break;
      }
      if (!pushed->has_event()) continue;  // a localization notice
      const auto received = Clock::now();
      recent_events_.add(pushed->event());
      out_.events({pushed->event()});
      stats_.count("events_sent");
      stats_.sample_ms("out.event_to_written", ms_between(received, Clock::now()));
    }
  }
}

}  // namespace scenewatch::ros
