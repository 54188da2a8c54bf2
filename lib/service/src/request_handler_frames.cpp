// The calls that bring a frame: IngestFrame (decoded from the message), IngestFile (read beneath
// a data root) and GetSurpriseMap of a given frame; all but the last go through process().
#include <algorithm>
#include <cmath>
#include <optional>
#include <system_error>

#include "proto_convert.h"
#include "request_handler_impl.h"
#include "scenewatch/core/files.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

/// True when `path` equals `root` or lies below it (component-wise, both canonical).
bool is_within(const fs::path& path, const fs::path& root) {
  auto [root_it, path_it] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  return root_it == root.end();
}

/// An error unless `k` is for a width x height image; `what` names the points ("the organized cloud").
Status check_intrinsics_fit(const Intrinsics& k, std::uint32_t width, std::uint32_t height, const std::string& what) {
  if (static_cast<std::uint32_t>(k.width) == width && static_cast<std::uint32_t>(k.height) == height) return {};
  return invalid_argument("intrinsics are for a " + std::to_string(k.width) + " x " + std::to_string(k.height) + " image but " +
                          what + " " + std::to_string(width) + " x " + std::to_string(height));
}

}  // namespace

/// The points of an IngestFrame that carries images: back-projected through its intrinsics, which
/// the frame keeps.
Result<Frame> RequestHandler::Impl::decode_rgbd_frame(const proto::IngestFrame& msg) {
  if (!msg.has_intrinsics()) return invalid_argument("rgbd needs intrinsics to back-project the depth image");
  auto images = convert::decode_rgbd(msg.rgbd());
  if (!images) return images.error();
  auto k = convert::decode_intrinsics(msg.intrinsics(), "intrinsics");
  if (!k) return k.error();
  const Status fits = check_intrinsics_fit(*k, static_cast<std::uint32_t>(images->depth.width),
                                           static_cast<std::uint32_t>(images->depth.height), "the rgbd images are");
  if (!fits) return fits.error();
  auto cloud = io::rgbd_to_cloud(images->color, images->depth, *k, io::kDepthMillimetres);
  if (!cloud) return cloud.error();
  Frame frame;
  frame.cloud = *cloud;
  frame.has_color = images->has_color;
  frame.intrinsics = *k;
  return frame;
}

Result<Frame> RequestHandler::Impl::decode_frame(const proto::IngestFrame& msg) {
  if (msg.has_cloud() && msg.has_rgbd()) return invalid_argument("both cloud and rgbd are set: send one");
  if (!msg.has_cloud() && !msg.has_rgbd()) return invalid_argument("cloud is missing (or rgbd, the images, with intrinsics)");
  Frame frame;
  if (msg.has_rgbd()) {
    auto images = decode_rgbd_frame(msg);
    if (!images) return images.error();
    frame = std::move(*images);
  } else {
    auto cloud = convert::decode_cloud(msg.cloud());
    if (!cloud) return cloud.error();
    frame.cloud = cloud->cloud;
    frame.has_color = cloud->has_color;
  }
  if (msg.has_pose()) {
    auto pose = convert::decode_pose(msg.pose(), "pose");
    if (!pose) return pose.error();
    frame.T_world_camera = *pose;
  }
  if (msg.has_intrinsics() && !frame.intrinsics) {  // an rgbd frame's were decoded with its images
    auto k = convert::decode_intrinsics(msg.intrinsics(), "intrinsics");
    if (!k) return k.error();
    if (frame.cloud->height > 1) {
      const Status fits = check_intrinsics_fit(*k, frame.cloud->width, frame.cloud->height, "the organized cloud is");
      if (!fits) return fits.error();
    }
    frame.intrinsics = *k;
  }
  if (!std::isfinite(msg.stamp_s())) return invalid_argument("stamp_s is not finite");
  frame.stamp_s = msg.stamp_s();
  frame.source = convert::source_label(msg.source());
  frame.camera = msg.camera();  // checked by the working memory with the rest of the frame
  auto mode = convert::decode_localization_mode(msg.localization());
  if (!mode) return mode.error();
  frame.localization = *mode;
  return frame;
}

Status RequestHandler::Impl::ingest_frame(const proto::IngestFrame& msg, proto::Response& response) {
  auto frame = decode_frame(msg);
  if (!frame) return frame.error();
  return process(*frame, response);
}

Status RequestHandler::Impl::get_surprise_map(const proto::GetSurpriseMap& msg, proto::Response& response) {
  std::shared_ptr<const pipeline::SurpriseResult> result;
  if (msg.has_frame()) {
    auto frame = decode_frame(msg.frame());
    if (!frame) return frame.error();
    auto computed = memory.surprise(*frame);
    if (!computed) return computed.error();
    result = *computed;
  } else {
    result = memory.last_surprise();
    if (!result) return not_found("no surprise map yet: ingest posed RGB-D frames (the first one becomes a keyframe)");
  }
  auto* out = response.mutable_surprise_map();
  const auto& map = result->map;
  out->set_width(static_cast<std::uint32_t>(map.width));
  out->set_height(static_cast<std::uint32_t>(map.height));
  out->set_total(convert::encode_floats(map.total));
  if (msg.include_channels()) {
    for (const auto& channel : map.channel) out->add_channels(convert::encode_floats(channel));
  }
  out->set_known_pixels(map.known_pixels);
  out->set_reference_views(static_cast<std::uint32_t>(result->reference_views));
  for (const auto& event : result->events) convert::to_proto(event, out->add_regions());
  convert::to_proto(result->T_world_camera, out->mutable_pose());
  convert::to_proto(result->intrinsics, out->mutable_intrinsics());
  out->set_stamp_s(result->stamp_s);
  out->set_compute_ms(result->ms);
  return {};
}

// Opens a client's path beneath the data root it names. The path is matched to a root as
// written (`..` folded) and, failing that or when it crosses a symlink the kernel will not follow
// beneath a root (an absolute one), with its symlinks resolved. Either way the kernel opens it
// beneath the root (open_beneath): a symlink swapped in after the match cannot lead out.
Result<FileBeneath> RequestHandler::Impl::open_under_roots(const fs::path& requested) const {
  if (config.data_roots.empty()) {
    return permission_denied("reading files on the server is disabled: no data roots are configured "
                             "(server.data_roots)");
  }
  std::optional<Error> refused;
  auto open_as = [&](const fs::path& candidate) -> std::optional<Result<FileBeneath>> {
    for (const auto& root : config.data_roots) {
      if (candidate.empty() || !is_within(candidate, root)) continue;
      auto file = open_beneath(root, candidate.lexically_relative(root));
      if (file || file.error().code != ErrorCode::kPermissionDenied) return file;
      refused = file.error();
    }
    return std::nullopt;
  };
  if (auto file = open_as(requested.lexically_normal())) return std::move(*file);
  std::error_code ec;  // only now the file system: the path's symlinks resolved
  if (auto file = open_as(fs::weakly_canonical(requested, ec))) return std::move(*file);
  std::string roots;
  for (const auto& root : config.data_roots) roots += (roots.empty() ? "" : ", ") + root.string();
  return permission_denied("'" + requested.string() + "' is outside the data roots (" + roots + ")" +
                           (refused ? ": " + refused->message : std::string()));
}

Status RequestHandler::Impl::ingest_file(const proto::IngestFile& msg, proto::Response& response) {
  if (msg.path().empty()) return invalid_argument("path is empty");
  const fs::path requested(msg.path());
  if (!requested.is_absolute()) return invalid_argument("path must be absolute, got '" + msg.path() + "'");
  auto file = open_under_roots(requested);
  if (!file) return file.error();
  if (file->size() > config.max_file_bytes) {
    return invalid_argument("'" + msg.path() + "' is " + std::to_string(file->size()) +
                            " bytes, more than server.max_file_bytes (" + std::to_string(config.max_file_bytes) + ")");
  }
  auto frame = io::load_cloud_frame(file->alias());
  if (!frame) {
    // Name the file the client asked for, not the private alias it was read through.
    Error e = frame.error();
    const std::string alias = file->alias().string();
    for (auto at = e.message.find(alias); at != std::string::npos; at = e.message.find(alias)) {
      e.message.replace(at, alias.size(), msg.path());
    }
    return e;
  }
  frame->source = msg.path();
  if (msg.has_pose()) {
    auto pose = convert::decode_pose(msg.pose(), "pose");
    if (!pose) return pose.error();
    frame->T_world_camera = *pose;
  }
  if (!std::isfinite(msg.stamp_s())) return invalid_argument("stamp_s is not finite");
  frame->stamp_s = msg.stamp_s();
  return process(*frame, response);
}

Status RequestHandler::Impl::process(const Frame& frame, proto::Response& response) {
  auto result = memory.process(frame);
  if (!result) return result.error();
  if (frame_observer) frame_observer(frame, *result);
  localization_notices.after_frame(frame.camera, result->localization);
  auto* out = response.mutable_ingest();
  out->set_frame_index(result->frame_index);
  out->set_points(result->points);
  for (const auto& plane : result->planes) convert::to_proto(plane, out->add_planes());
  for (const auto& cluster : result->objects) convert::to_proto(cluster, out->add_clusters());
  for (const auto& event : result->events) convert::to_proto(event, out->add_events());
  out->set_segment_ms(result->segment_ms);
  out->set_insert_ms(result->insert_ms);
  out->set_total_ms(result->total_ms);
  out->set_frames_skipped(frames_skipped.load());
  convert::to_proto(result->localization, out->mutable_localization());
  return {};
}

}  // namespace scenewatch::service
