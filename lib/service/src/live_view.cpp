#include "scenewatch/service/live_view.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include "class_records.h"
#include "live_view_page.h"
#include "proto_convert.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/core/event_json.h"
#include "scenewatch/core/scene_json.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/pipeline/scene_snapshot.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::service {
using nlohmann::json;

namespace {

// A camera's name is the frames' (only control characters are refused): a byte that is not
// UTF-8 becomes U+FFFD rather than an exception, which would answer the whole state with 500.
std::string dump_text(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

HttpResponse json_response(const json& j) {
  HttpResponse r;
  r.content_type = "application/json";
  r.body = dump_text(j);
  return r;
}

/// Millimetres are enough for display and keep the numbers short.
double mm(double v) { return std::round(v * 1000.0) / 1000.0; }

/// The event's JSON (event_json.h) without its point indices, which are of no use in a browser.
json event_json(const Event& event) {
  json j = to_json(event);
  j.erase("indices_before");
  j.erase("indices_after");
  return j;
}

/// The changes seen but not yet confirmed, field for field as GetPendingChanges answers them;
/// the box in metres as measured, like the objects' boxes (not rounded: a client may compare).
json pending_json(const std::vector<pipeline::PendingChangeSeen>& pending) {
  const auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  json out = json::array();
  for (const auto& seen : pending) {
    const change::PendingChange& c = seen.change;
    out.push_back({{"id", c.id}, {"kind", proto::PendingChange::Kind_Name(convert::to_proto(c.kind))},
                   {"box_world", {{"min", vec(c.box_world.min)}, {"max", vec(c.box_world.max)}}},
                   {"centroid_world", vec(c.centroid_world)}, {"hits", c.hits}, {"hits_needed", c.hits_needed},
                   {"camera", seen.camera}});
  }
  return out;
}

std::string sse_message(const Event& event) {
  return "id: " + std::to_string(event.id) + "\ndata: " + dump_text(event_json(event)) + "\n\n";
}

}  // namespace

struct LiveView::Impl {
  pipeline::WorkingMemory& memory;
  LiveViewConfig config;
  int subscription = -1;

  std::mutex frame_mutex;
  std::optional<Frame> last_frame;
  std::shared_ptr<const pipeline::SurpriseResult> last_surprise;
  std::uint64_t last_frame_index = 0;  ///< frames observed
  std::uint64_t png_frame_index = 0;  ///< the frame `png` shows (0: none yet)
  std::string png;

  std::mutex streams_mutex;
  std::vector<std::shared_ptr<HttpStream>> streams;

  Impl(pipeline::WorkingMemory& m, LiveViewConfig c) : memory(m), config(std::move(c)) {}

  void broadcast(const Event& event) {
    const std::string message = sse_message(event);
    std::lock_guard<std::mutex> lock(streams_mutex);
    std::vector<std::shared_ptr<HttpStream>> still_open;
    for (auto& s : streams)
      if (s->send(message)) still_open.push_back(std::move(s));
    streams = std::move(still_open);
  }

  HttpResponse page() const {
    HttpResponse r;
    r.content_type = "text/html; charset=utf-8";
    r.body = std::string(live_view_page());
    return r;
  }

  HttpResponse three_js() const {
    std::ifstream in(config.three_js, std::ios::binary);
    if (!in) {
      return http_error(404, "three.js is not at '" + config.three_js.string() +
                                 "': install Debian's libjs-three or set server.http_three_js");
    }
    std::ostringstream bytes;
    bytes << in.rdbuf();
    HttpResponse r;
    r.content_type = "application/javascript; charset=utf-8";
    r.body = bytes.str();
    return r;
  }

  // The last NextBestView answer's views: T_world_camera row-major (as the API's Pose), the
  // score, and the field of view to draw each camera's frustum with.
  json suggested_views_json() const {
    json out = {{"answer", 0}, {"views", json::array()}};
    if (!config.suggested_views) return out;
    const SuggestedViewSet set = config.suggested_views->last();
    out["answer"] = set.answer;
    out["measure"] = set.measure;
    out["horizontal_fov_deg"] = set.horizontal_fov_deg;
    out["vertical_fov_deg"] = set.vertical_fov_deg;
    out["target"] = {{"min", {mm(set.target.min.x()), mm(set.target.min.y()), mm(set.target.min.z())}},
                     {"max", {mm(set.target.max.x()), mm(set.target.max.y()), mm(set.target.max.z())}}};
    for (const SuggestedView& v : set.views) {
      json pose = json::array();
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) pose.push_back(v.T_world_camera.matrix()(r, c));
      out["views"].push_back({{"pose", pose}, {"score", v.score}});
    }
    return out;
  }

  /// With `with_voxels` false, the "voxels" key is left out: the page polls that way and asks
  /// for them only when a frame was processed.
  HttpResponse state(bool with_voxels) const {
    const auto snapshot = memory.snapshot();
    const pipeline::Stats stats = memory.stats();
    json planes = json::array();
    for (const auto& p : snapshot->planes) planes.push_back(to_json(p));
    json objects = json::array();
    for (const auto& o : snapshot->objects) objects.push_back(to_json(o));
    // The classes only in the whole state, which the page asks for when a frame was processed:
    // describing is cached per object, but the cheap poll should not start it.
    if (with_voxels && config.classes) {
      const auto described = describe_and_record(memory, *snapshot, *config.classes);
      for (std::size_t k = 0; k < described.size(); ++k) {
        if (!described[k]) continue;  // an object without points
        objects[k]["class"] = described[k]->class_name;
        objects[k]["class_score"] = described[k]->score;
      }
    }
    json state = {{"frames_processed", snapshot->frames_processed},
                  {"last_stamp_s", snapshot->last_stamp_s},
                  {"stats",
                   {{"frames_processed", stats.frames_processed}, {"points_processed", stats.points_processed},
                    {"events_emitted", stats.events_emitted}, {"tracked_objects", stats.tracked_objects},
                    {"map_occupied_leaves", stats.map_occupied_leaves}, {"map_memory_bytes", stats.map_memory_bytes},
                    {"map_resolution_m", stats.map_resolution_m}, {"last_frame_ms", stats.last_frame_ms},
                    {"mean_frame_ms", stats.mean_frame_ms}, {"keyframes", stats.keyframes}}},
                  {"planes", planes},
                  {"objects", objects},
                  {"views", suggested_views_json()},
                  {"pending", pending_json(snapshot->pending)}};
    if (with_voxels) {
      const pipeline::OccupiedVoxels voxels = memory.occupied_voxels(config.max_voxels);
      std::vector<double> centers;
      centers.reserve(3 * voxels.centers_world.size());
      for (const auto& c : voxels.centers_world) {
        centers.push_back(mm(c.x()));
        centers.push_back(mm(c.y()));
        centers.push_back(mm(c.z()));
      }
      state["voxels"] = {{"resolution_m", voxels.resolution_m}, {"total", voxels.total}, {"stride", voxels.stride},
                         {"count", voxels.centers_world.size()}, {"centers_world", centers}};
    }
    return json_response(state);
  }

  HttpResponse frame_png() {
    std::unique_lock<std::mutex> lock(frame_mutex);
    if (!last_frame) return http_error(404, "no frame has been processed yet");
    if (png_frame_index != last_frame_index) {
      const Frame frame = *last_frame;
      const auto surprise = last_surprise;
      const std::uint64_t index = last_frame_index;
      lock.unlock();  // the conversion must not hold up observe() on the processing thread
      auto keyframe = background::keyframe_from_frame(frame);
      if (!keyframe) return http_error(404, "the last frame has no colour image: " + keyframe.error().message);
      ColorImage image = keyframe->color;
      if (surprise && surprise->map.width == image.width && surprise->map.height == image.height) {
        image = surprise::heatmap_overlay(surprise->map, image);
      }
      auto encoded = io::encode_color_png(image);
      if (!encoded) return http_error(500, encoded.error().message);
      lock.lock();
      png = std::move(*encoded);
      png_frame_index = index;
    }
    HttpResponse r;
    r.content_type = "image/png";
    r.body = png;
    return r;
  }

  HttpResponse events(const HttpRequest& request) {
    if (request.has_query("since")) {
      std::uint64_t since = 0;
      const std::string value = request.query_value("since");
      try {
        std::size_t used = 0;
        since = std::stoull(value, &used);
        if (used != value.size() || value.empty() || value[0] == '-') throw std::invalid_argument(value);
      } catch (const std::exception&) {
        return http_error(400, "since: expected an event id (a whole number >= 0), got '" + value + "'");
      }
      json list = json::array();
      for (const auto& e : memory.events_since(since, config.max_backlog_events)) list.push_back(event_json(e));
      return json_response({{"events", list}});
    }
    // The stream carries the events emitted from now on; the page asks for the backlog with
    // ?since=N once the stream is open and keeps each id once.
    HttpResponse r;
    r.content_type = "text/event-stream";
    r.body = "retry: 2000\n\n";
    r.heartbeat = ": heartbeat\n\n";  // a comment: EventSource ignores it
    r.on_stream = [this](std::shared_ptr<HttpStream> stream) {
      std::lock_guard<std::mutex> lock(streams_mutex);
      streams.push_back(std::move(stream));
    };
    return r;
  }
};

LiveView::LiveView(pipeline::WorkingMemory& memory, LiveViewConfig config)
    : impl_(std::make_unique<Impl>(memory, std::move(config))) {
  impl_->subscription = memory.subscribe([impl = impl_.get()](const Event& e) { impl->broadcast(e); });
}

LiveView::~LiveView() { impl_->memory.unsubscribe(impl_->subscription); }

void LiveView::observe(const Frame& frame, const pipeline::FrameResult& result) {
  std::lock_guard<std::mutex> lock(impl_->frame_mutex);
  impl_->last_frame = frame;
  if (result.surprise) impl_->last_surprise = result.surprise;
  else impl_->last_surprise.reset();
  ++impl_->last_frame_index;  // counts observed frames: never 0, which means "no PNG yet"
}

HttpResponse LiveView::handle(const HttpRequest& request) {
  Impl& s = *impl_;
  if (request.path == "/" || request.path == "/index.html") return s.page();
  if (request.path == "/three.min.js") return s.three_js();
  if (request.path == "/api/state") return s.state(request.query_value("voxels") != "0");
  if (request.path == "/api/frame.png") return s.frame_png();
  if (request.path == "/api/events") return s.events(request);
  return http_error(404, "no such page: the live view serves /, /three.min.js, /api/state, /api/frame.png and "
                         "/api/events");
}

Status LiveView::check_three_js() const {
  std::ifstream in(impl_->config.three_js, std::ios::binary);
  if (!in) {
    return not_found("three.js is not at '" + impl_->config.three_js.string() +
                     "': the page's 3D view stays empty (install Debian's libjs-three, or set server.http_three_js)");
  }
  return {};
}

}  // namespace scenewatch::service
