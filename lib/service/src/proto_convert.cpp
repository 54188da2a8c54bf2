#include "proto_convert.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

namespace scenewatch::service::convert {
namespace {

// The wire format is little-endian whatever the host is.
void put_float_le(float value, char* out) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  out[0] = static_cast<char>(bits & 0xFF);
  out[1] = static_cast<char>((bits >> 8) & 0xFF);
  out[2] = static_cast<char>((bits >> 16) & 0xFF);
  out[3] = static_cast<char>((bits >> 24) & 0xFF);
}

float get_float_le(const char* in) {
  const auto* b = reinterpret_cast<const unsigned char*>(in);
  const std::uint32_t bits = std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) |
                             (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[3]} << 24);
  float value = 0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace

std::string encode_floats(const std::vector<float>& values) {
  std::string out(4 * values.size(), '\0');
  for (std::size_t i = 0; i < values.size(); ++i) put_float_le(values[i], &out[4 * i]);
  return out;
}

Result<std::vector<float>> decode_floats(const std::string& bytes, const std::string& field) {
  if (bytes.size() % 4 != 0)
    return invalid_argument(field + ": " + std::to_string(bytes.size()) + " bytes is not a whole number of float32");
  std::vector<float> out(bytes.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = get_float_le(&bytes[4 * i]);
  return out;
}

namespace {

proto::Event::Level to_proto(EventLevel level) {
  switch (level) {
    case EventLevel::kMismatch: return proto::Event::MISMATCH;
    case EventLevel::kPrediction: return proto::Event::PREDICTION;
    case EventLevel::kImplausibility: return proto::Event::IMPLAUSIBILITY;
  }
  return proto::Event::LEVEL_UNSPECIFIED;
}

proto::Event::Kind to_proto(EventKind kind) {
  switch (kind) {
    case EventKind::kObjectAppeared: return proto::Event::OBJECT_APPEARED;
    case EventKind::kObjectGone: return proto::Event::OBJECT_GONE;
    case EventKind::kAppearanceChange: return proto::Event::APPEARANCE_CHANGE;
    case EventKind::kObjectAdded: return proto::Event::OBJECT_ADDED;
    case EventKind::kObjectRemoved: return proto::Event::OBJECT_REMOVED;
    case EventKind::kObjectMoved: return proto::Event::OBJECT_MOVED;
    case EventKind::kFrozenDofMotion: return proto::Event::FROZEN_DOF_MOTION;
    case EventKind::kObjectPromoted: return proto::Event::OBJECT_PROMOTED;
  }
  return proto::Event::KIND_UNSPECIFIED;
}

}  // namespace

proto::Status::Code to_proto(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument: return proto::Status::INVALID_ARGUMENT;
    case ErrorCode::kNotFound: return proto::Status::NOT_FOUND;
    case ErrorCode::kIoError: return proto::Status::IO_ERROR;
    case ErrorCode::kPermissionDenied: return proto::Status::PERMISSION_DENIED;
    case ErrorCode::kUnavailable: return proto::Status::UNAVAILABLE;
    case ErrorCode::kInternal: return proto::Status::INTERNAL;
  }
  return proto::Status::INTERNAL;
}

ErrorCode from_proto(proto::Status::Code code) {
  switch (code) {
    case proto::Status::INVALID_ARGUMENT: return ErrorCode::kInvalidArgument;
    case proto::Status::NOT_FOUND: return ErrorCode::kNotFound;
    case proto::Status::IO_ERROR: return ErrorCode::kIoError;
    case proto::Status::PERMISSION_DENIED: return ErrorCode::kPermissionDenied;
    case proto::Status::UNAVAILABLE: return ErrorCode::kUnavailable;
    case proto::Status::UNKNOWN_REQUEST: return ErrorCode::kInvalidArgument;
    default: return ErrorCode::kInternal;
  }
}

void to_proto(const Eigen::Vector3d& v, proto::Vec3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

Eigen::Vector3d from_proto(const proto::Vec3& v) { return {v.x(), v.y(), v.z()}; }

void to_proto(const Aabb& box, proto::Box* out) {
  to_proto(box.min, out->mutable_min());
  to_proto(box.max, out->mutable_max());
}

void to_proto(const OrientedBox& box, proto::OrientedBox* out) {
  to_proto(box.center, out->mutable_center());
  auto* q = out->mutable_rotation();
  q->set_w(box.rotation.w());
  q->set_x(box.rotation.x());
  q->set_y(box.rotation.y());
  q->set_z(box.rotation.z());
  to_proto(box.extents, out->mutable_extents());
}

void to_proto(const Plane& plane, proto::Plane* out) {
  out->set_id(plane.id);
  to_proto(plane.normal, out->mutable_normal());
  out->set_d(plane.d);
  for (const auto& p : plane.hull) to_proto(p, out->add_hull());
  out->set_area_m2(plane.area_m2);
  out->set_inlier_count(plane.inlier_count);
  to_proto(plane.centroid, out->mutable_centroid());
}

void to_proto(const ObjectCluster& cluster, proto::Cluster* out) {
  out->set_plane_id(cluster.plane_id);
  to_proto(cluster.centroid, out->mutable_centroid());
  to_proto(cluster.box, out->mutable_box());
  out->set_point_count(cluster.point_count);
  to_proto(Eigen::Vector3d(cluster.mean_rgb.cast<double>()), out->mutable_mean_rgb());
  out->set_supported_by(cluster.supported_by);
}

void to_proto(const TrackedObject& object, proto::Object* out) {
  out->set_id(object.id);
  out->set_plane_id(object.cluster.plane_id);
  to_proto(object.cluster.centroid, out->mutable_centroid());
  to_proto(object.cluster.box, out->mutable_box());
  out->set_point_count(object.cluster.point_count);
  to_proto(Eigen::Vector3d(object.cluster.mean_rgb.cast<double>()), out->mutable_mean_rgb());
  out->set_first_seen_s(object.first_seen_s);
  out->set_last_seen_s(object.last_seen_s);
  out->set_observations(static_cast<std::uint32_t>(std::max(0, object.observations)));
  out->set_supported_by(object.supported_by);
  if (!object.foreground) return;
  const ForegroundState& f = *object.foreground;
  out->set_foreground(true);
  to_proto(f.T_world_object, out->mutable_pose());
  for (int k = 0; k < kDofCount; ++k) {
    const char* name = to_string(static_cast<Dof>(k));
    if (f.free[static_cast<std::size_t>(k)]) out->add_free_dofs(name);
    else out->add_frozen_dofs(name);
  }
  for (const auto& h : f.handlings) {
    auto* ph = out->add_handlings();
    ph->set_start_s(h.start_s);
    ph->set_end_s(h.end_s);
    for (int k = 0; k < kDofCount; ++k) {
      ph->add_dof_range(h.range[static_cast<std::size_t>(k)]);
      if (h.moved[static_cast<std::size_t>(k)]) ph->add_moved_dofs(to_string(static_cast<Dof>(k)));
    }
  }
  out->set_in_hand(f.in_hand);
  out->set_visible(f.visible);
  out->set_promoted_s(f.promoted_s);
}

void to_proto(const Event& event, proto::Event* out) {
  out->set_id(event.id);
  out->set_stamp_s(event.stamp_s);
  out->set_level(to_proto(event.level));
  out->set_kind(to_proto(event.kind));
  out->set_score(event.score);
  to_proto(event.box_world, out->mutable_box_world());
  to_proto(event.centroid_world, out->mutable_centroid_world());
  if (event.object_id) out->set_object_id(*event.object_id);
  out->set_detail(event.detail);
  for (const auto& [name, value] : event.evidence) (*out->mutable_evidence())[name] = value;
  if (event.region) {
    auto* r = out->mutable_region();
    r->set_x(event.region->x);
    r->set_y(event.region->y);
    r->set_width(event.region->width);
    r->set_height(event.region->height);
    r->set_area(event.region->area);
  }
  if (event.displacement_world) to_proto(*event.displacement_world, out->mutable_displacement_world());
  out->mutable_indices_before()->Add(event.indices_before.begin(), event.indices_before.end());
  out->mutable_indices_after()->Add(event.indices_after.begin(), event.indices_after.end());
  out->mutable_pending_ids()->Add(event.pending_ids.begin(), event.pending_ids.end());
}

void to_proto(const Pose& pose, proto::Pose* out) {
  const Eigen::Matrix4d m = pose.matrix();
  out->clear_matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out->add_matrix(m(r, c));
  }
}

void to_proto(const localization::Localization& where, proto::LocalizationResult* out) {
  out->set_mode(localization::mode_name(where.mode));
  out->set_state(localization::state_name(where.state));
  to_proto(where.T_world_camera, out->mutable_pose());
  out->set_correction_m(where.correction_m);
  out->set_correction_deg(where.correction_deg);
  out->set_inlier_fraction(where.inlier_fraction);
  out->set_residual_m(where.residual_m);
  out->set_reference_keyframe(where.reference_keyframe);
  out->set_reason(where.reason);
  out->set_compute_ms(where.ms);
  to_proto(where.T_world_odom, out->mutable_t_world_odom());
  out->set_relocalized(where.relocalized);
  out->set_homed(where.homed);
  out->set_feature_matches(where.feature_matches);
  out->set_feature_inliers(where.feature_inliers);
  out->set_relocalization_ms(where.relocalization_ms);
  out->set_odom_change_m(where.odom_change_m);
  out->set_odom_change_deg(where.odom_change_deg);
}

proto::PendingChange::Kind to_proto(change::PendingKind kind) {
  switch (kind) {
    case change::PendingKind::kAdded: return proto::PendingChange::ADDED;
    case change::PendingKind::kRemoved: return proto::PendingChange::REMOVED;
    case change::PendingKind::kAppearance: return proto::PendingChange::APPEARANCE_CHANGE;
  }
  return proto::PendingChange::KIND_UNSPECIFIED;
}

proto::LocalizationMode to_proto(const std::optional<LocalizationMode>& mode) {
  if (!mode) return proto::LOCALIZATION_CONFIGURED;
  switch (*mode) {
    case LocalizationMode::kGiven: return proto::LOCALIZATION_GIVEN;
    case LocalizationMode::kRefine: return proto::LOCALIZATION_REFINE;
    case LocalizationMode::kTrack: return proto::LOCALIZATION_TRACK;
  }
  return proto::LOCALIZATION_CONFIGURED;
}

Result<std::optional<LocalizationMode>> decode_localization_mode(int value) {
  switch (value) {
    case proto::LOCALIZATION_CONFIGURED: return std::optional<LocalizationMode>{};
    case proto::LOCALIZATION_GIVEN: return std::optional<LocalizationMode>{LocalizationMode::kGiven};
    case proto::LOCALIZATION_REFINE: return std::optional<LocalizationMode>{LocalizationMode::kRefine};
    case proto::LOCALIZATION_TRACK: return std::optional<LocalizationMode>{LocalizationMode::kTrack};
  }
  return invalid_argument("localization: unknown mode " + std::to_string(value));
}

void to_proto(const Intrinsics& intrinsics, proto::Intrinsics* out) {
  out->set_fx(intrinsics.fx);
  out->set_fy(intrinsics.fy);
  out->set_cx(intrinsics.cx);
  out->set_cy(intrinsics.cy);
  out->set_width(static_cast<std::uint32_t>(std::max(0, intrinsics.width)));
  out->set_height(static_cast<std::uint32_t>(std::max(0, intrinsics.height)));
}

void encode_cloud(const Cloud& cloud, bool has_color, proto::Cloud* out) {
  const std::size_t n = cloud.points.size();
  const bool organized = cloud.height > 1 && std::size_t{cloud.width} * cloud.height == n;
  out->set_width(organized ? cloud.width : static_cast<std::uint32_t>(n));
  out->set_height(organized ? cloud.height : 1);
  std::string* xyz = out->mutable_xyz();
  xyz->resize(12 * n);
  char* dst = xyz->data();
  for (const auto& p : cloud.points) {
    put_float_le(p.x, dst);
    put_float_le(p.y, dst + 4);
    put_float_le(p.z, dst + 8);
    dst += 12;
  }
  if (!has_color) {
    out->clear_rgb();
    return;
  }
  std::string* rgb = out->mutable_rgb();
  rgb->resize(3 * n);
  char* c = rgb->data();
  for (const auto& p : cloud.points) {
    c[0] = static_cast<char>(p.r);
    c[1] = static_cast<char>(p.g);
    c[2] = static_cast<char>(p.b);
    c += 3;
  }
}

Result<DecodedCloud> decode_cloud(const proto::Cloud& msg) {
  const std::uint64_t n = std::uint64_t{msg.width()} * msg.height();
  if (n == 0) {
    return invalid_argument("cloud is empty: width x height = " + std::to_string(msg.width()) + " x " +
                            std::to_string(msg.height()));
  }
  const std::string dims = std::to_string(msg.width()) + " x " + std::to_string(msg.height());
  if (n > std::numeric_limits<std::uint64_t>::max() / 12) {
    return invalid_argument("cloud declares " + dims + " points, more than any message can hold");
  }
  if (msg.xyz().size() != 12 * n) {
    return invalid_argument("cloud.xyz has " + std::to_string(msg.xyz().size()) + " bytes, expected " +
                            std::to_string(12 * n) + " (12 bytes per point for " + dims + " points)");
  }
  const bool has_color = !msg.rgb().empty();
  if (has_color && msg.rgb().size() != 3 * n) {
    return invalid_argument("cloud.rgb has " + std::to_string(msg.rgb().size()) + " bytes, expected 0 or " +
                            std::to_string(3 * n) + " (3 bytes per point for " + dims + " points)");
  }
  auto cloud = std::make_shared<Cloud>();
  cloud->width = msg.width();
  cloud->height = msg.height();
  cloud->points.resize(static_cast<std::size_t>(n));
  const char* xyz = msg.xyz().data();
  const auto* rgb = reinterpret_cast<const unsigned char*>(msg.rgb().data());
  bool dense = true;
  for (std::size_t i = 0; i < cloud->points.size(); ++i) {
    PointT& p = cloud->points[i];
    p.x = get_float_le(xyz + 12 * i);
    p.y = get_float_le(xyz + 12 * i + 4);
    p.z = get_float_le(xyz + 12 * i + 8);
    if (has_color) {
      p.r = rgb[3 * i];
      p.g = rgb[3 * i + 1];
      p.b = rgb[3 * i + 2];
    } else {
      p.r = p.g = p.b = 128;
    }
    p.a = 255;
    dense = dense && is_valid(p);
  }
  cloud->is_dense = dense;
  return DecodedCloud{std::move(cloud), has_color};
}

void encode_rgbd(const DepthImage& depth, const ColorImage* color, proto::RgbdImages* out) {
  out->set_width(static_cast<std::uint32_t>(depth.width));
  out->set_height(static_cast<std::uint32_t>(depth.height));
  std::string* bytes = out->mutable_depth_mm();
  bytes->resize(2 * depth.depth_mm.size());
  const std::uint16_t probe = 1;
  if (*reinterpret_cast<const unsigned char*>(&probe) == 1) {  // a little-endian host: the bytes as they are
    std::memcpy(bytes->data(), depth.depth_mm.data(), bytes->size());
  } else {
    for (std::size_t i = 0; i < depth.depth_mm.size(); ++i) {
      (*bytes)[2 * i] = static_cast<char>(depth.depth_mm[i] & 0xff);
      (*bytes)[2 * i + 1] = static_cast<char>(depth.depth_mm[i] >> 8);
    }
  }
  if (color) out->mutable_rgb()->assign(reinterpret_cast<const char*>(color->rgb.data()), color->rgb.size());
}

Result<DecodedRgbd> decode_rgbd(const proto::RgbdImages& msg) {
  const std::string dims = std::to_string(msg.width()) + " x " + std::to_string(msg.height());
  if (msg.width() == 0 || msg.height() == 0 || msg.width() > 100000 || msg.height() > 100000) {
    return invalid_argument("rgbd images of " + dims + " pixels (1 to 100000 on a side)");
  }
  const std::size_t n = std::size_t{msg.width()} * msg.height();
  if (msg.depth_mm().size() != 2 * n) {
    return invalid_argument("rgbd.depth_mm has " + std::to_string(msg.depth_mm().size()) + " bytes, expected " +
                            std::to_string(2 * n) + " (2 bytes per pixel for " + dims + " pixels)");
  }
  const bool has_color = !msg.rgb().empty();
  if (has_color && msg.rgb().size() != 3 * n) {
    return invalid_argument("rgbd.rgb has " + std::to_string(msg.rgb().size()) + " bytes, expected 0 or " +
                            std::to_string(3 * n) + " (3 bytes per pixel for " + dims + " pixels)");
  }
  DecodedRgbd out;
  out.has_color = has_color;
  out.depth.width = out.color.width = static_cast<int>(msg.width());
  out.depth.height = out.color.height = static_cast<int>(msg.height());
  out.depth.depth_mm.resize(n);
  const auto* d = reinterpret_cast<const unsigned char*>(msg.depth_mm().data());
  for (std::size_t i = 0; i < n; ++i) out.depth.depth_mm[i] = static_cast<std::uint16_t>(d[2 * i] | (d[2 * i + 1] << 8));
  if (has_color) {
    out.color.rgb.assign(msg.rgb().begin(), msg.rgb().end());
  } else {
    out.color.rgb.assign(3 * n, 128);
  }
  return out;
}

Result<Pose> decode_pose(const proto::Pose& msg, const std::string& field) {
  if (msg.matrix_size() != 16) {
    return invalid_argument(field + ".matrix must have 16 values (row-major 4x4), got " +
                            std::to_string(msg.matrix_size()));
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = msg.matrix(4 * r + c);
  }
  if (Status status = validate_rigid(m); !status) return invalid_argument(field + ": " + status.error().message);
  return pose_from_matrix(m);
}

Result<Eigen::Vector3d> decode_point(const proto::Vec3& msg, const std::string& field) {
  const Eigen::Vector3d p = from_proto(msg);
  if (!p.allFinite()) return invalid_argument(field + " has non-finite coordinates");
  return p;
}

Result<Aabb> decode_box(const proto::Box& msg, const std::string& field) {
  Aabb box{from_proto(msg.min()), from_proto(msg.max())};
  if (!box.min.allFinite() || !box.max.allFinite()) return invalid_argument(field + " has non-finite coordinates");
  if (!(box.min.array() <= box.max.array()).all()) {
    std::ostringstream os;
    os << field << ": min (" << box.min.transpose() << ") must be <= max (" << box.max.transpose()
       << ") in every coordinate";
    return invalid_argument(os.str());
  }
  return box;
}

Result<Intrinsics> decode_intrinsics(const proto::Intrinsics& msg, const std::string& field) {
  Intrinsics k;
  k.fx = msg.fx();
  k.fy = msg.fy();
  k.cx = msg.cx();
  k.cy = msg.cy();
  if (msg.width() > 1u << 20 || msg.height() > 1u << 20) {
    return invalid_argument(field + ": image size " + std::to_string(msg.width()) + " x " +
                            std::to_string(msg.height()) + " is implausible");
  }
  k.width = static_cast<int>(msg.width());
  k.height = static_cast<int>(msg.height());
  if (!std::isfinite(k.fx) || !std::isfinite(k.fy) || !std::isfinite(k.cx) || !std::isfinite(k.cy)) {
    return invalid_argument(field + " has non-finite values");
  }
  if (!k.valid()) return invalid_argument(field + ": fx, fy, width and height must be positive");
  return k;
}

namespace {
/// The length of the well-formed UTF-8 character at the start of `s`, 0 when there is none (RFC 3629:
/// no overlong forms, no surrogates, nothing above U+10FFFF).
std::size_t utf8_char_length(std::string_view s) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    n = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    n = 3;
    if (lead == 0xE0) lo = 0xA0;
    if (lead == 0xED) hi = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    n = 4;
    if (lead == 0xF0) lo = 0x90;
    if (lead == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (s.size() < n || byte(1) < lo || byte(1) > hi) return 0;
  for (std::size_t i = 2; i < n; ++i) {
    if ((byte(i) & 0xC0) != 0x80) return 0;
  }
  return n;
}
}  // namespace

std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  while (!text.empty()) {
    const std::size_t n = utf8_char_length(text);
    if (n == 0) {
      out += '?';
      text.remove_prefix(1);
    } else {
      out.append(text.substr(0, n));
      text.remove_prefix(n);
    }
  }
  return out;
}

std::string source_label(const std::string& sent) {
  if (sent.empty()) return "api";
  std::size_t keep = std::min(sent.size(), kMaxSourceLabelBytes);
  // Not in the middle of a character: back off over UTF-8 continuation bytes (10xxxxxx).
  while (keep < sent.size() && keep > 0 && (static_cast<unsigned char>(sent[keep]) & 0xC0) == 0x80) --keep;
  std::string label = sent.substr(0, keep);
  for (char& c : label) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';  // one log line per message
  }
  if (keep < sent.size()) label += "... (cut from " + std::to_string(sent.size()) + " bytes)";
  return label;
}

}  // namespace scenewatch::service::convert
